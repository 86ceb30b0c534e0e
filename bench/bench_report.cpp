#include "bench_report.hpp"

#include <fmt/format.h>

#include <fstream>

namespace cleave::bench {
namespace {

nlohmann::json time_or_null(const StageFigures& s) {
  return s.time.count > 0 ? nlohmann::json(s.time.median_ms) : nlohmann::json(nullptr);
}

nlohmann::json implementation_json(const ImplementationFigures& f) {
  nlohmann::json j;
  j["solver"] = f.solver;
  nlohmann::json iterations = nlohmann::json::object(), range = nlohmann::json::object(),
                 skipped = nlohmann::json::object(), difference = nlohmann::json::object();
  for (Stage s : kAllStages) {
    const StageFigures& st = f.stage(s);
    const std::string key(stage_key(s));
    j["ms_" + key] = time_or_null(st);
    if (st.time.count > 0) {
      iterations[key] = st.iterations;
      range[key] = {st.time.min_ms, st.time.max_ms};
    }
    if (!st.skipped.empty()) skipped[key] = st.skipped;
    if (st.relative_difference) difference[key] = *st.relative_difference;
  }
  j["peak_mb"] = f.peak_mb;
  j["iterations"] = iterations;
  j["range_ms"] = range;
  if (!skipped.empty()) j["skipped"] = skipped;
  if (!difference.empty()) j["relative_difference"] = difference;
  return j;
}

std::string ms_text(const StageFigures& s) {
  if (s.time.count == 0) return "-";
  return s.time.median_ms >= 100 ? fmt::format("{:.0f}", s.time.median_ms) : fmt::format("{:.3g}", s.time.median_ms);
}

}  // namespace

std::string cpu_model_name() {
  std::ifstream cpuinfo("/proc/cpuinfo");
  std::string line;
  while (std::getline(cpuinfo, line))
    if (line.rfind("model name", 0) == 0) {
      const auto colon = line.find(':');
      if (colon != std::string::npos) return line.substr(line.find_first_not_of(' ', colon + 1));
    }
  return "unknown";
}

nlohmann::json model_figures_json(const ModelFigures& figures, const MachineFigures& machine) {
  nlohmann::json j = implementation_json(figures.cleave);
  j["model"] = figures.model.key;
  j["shape"] = figures.model.shape;
  j["resolution"] = {figures.model.cells.x(), figures.model.cells.y(), figures.model.cells.z()};
  j["cells"] = figures.cells;
  j["vertices"] = figures.vertices;
  j["incisions"] = figures.incisions;
  j["design_equilibrium_weight"] = figures.design_equilibrium_weight;
  j["stiffness_nonzeros"] = figures.stiffness_nonzeros;
  j["residual_stress"] = figures.residual_stress;
  j["machine"] = {{"cpu", machine.cpu},
                  {"threads", machine.threads},
                  {"bandwidth_GB_per_s", machine.bandwidth.all_threads_GB_per_s},
                  {"bandwidth_one_thread_GB_per_s", machine.bandwidth.one_thread_GB_per_s},
                  {"malloc_huge_pages", machine.malloc_huge_pages}};
  if (figures.model.paper) {
    const PaperFigures& p = *figures.model.paper;
    j["paper_2012"] = {{"cells", p.cells}, {"vertices", p.vertices}, {"ms_vector", p.ms_vector},
                       {"ms_value", p.ms_value}, {"ms_step", p.ms_step}};
  }
  nlohmann::json peers = nlohmann::json::object();
  for (const ImplementationFigures& peer : figures.peers)
    peers[std::string(implementation_key(peer.implementation))] = implementation_json(peer);
  j["peers"] = peers;
  return j;
}

std::string stage_table(const std::vector<ModelFigures>& models) {
  std::string out = fmt::format("{:<14} {:>8} {:<12} {:>22} {:>6}", "model", "cells", "stage", "cleave ms (min-max)", "iter");
  if (!models.empty())
    for (const ImplementationFigures& peer : models.front().peers) out += fmt::format(" {:>10}", implementation_key(peer.implementation));
  out += "\n";
  for (const ModelFigures& m : models)
    for (Stage s : kAllStages) {
      const StageFigures& st = m.cleave.stage(s);
      if (st.time.count == 0 && !m.peers.empty() && m.peers.front().stage(s).time.count == 0) continue;
      const std::string range = st.time.count == 0 ? "-"
                                                   : fmt::format("{} ({:.3g}-{:.3g})", ms_text(st), st.time.min_ms, st.time.max_ms);
      out += fmt::format("{:<14} {:>8} {:<12} {:>22} {:>6}", m.model.key, m.cells, stage_key(s), range, st.iterations);
      for (const ImplementationFigures& peer : m.peers) out += fmt::format(" {:>10}", ms_text(peer.stage(s)));
      out += "\n";
    }
  for (const ModelFigures& m : models)  // why a stage was not run for cleave, once per model and reason
    for (Stage s : kAllStages) {
      const std::string& why = m.cleave.stage(s).skipped;
      if (why.empty()) continue;
      bool first = true;
      for (Stage earlier : kAllStages) {
        if (earlier == s) break;
        if (m.cleave.stage(earlier).skipped == why) first = false;
      }
      if (first) out += fmt::format("{}: skipped ({}): {}\n", m.model.key, m.residual_stress == "prescribed" ? "design stages and update; preview and step on the prescribed 20/10 kPa stress" : stage_key(s), why);
    }
  return out;
}

std::string ratio_table(const std::vector<ModelFigures>& models) {
  std::string out = fmt::format("{:<14} {:<12}", "model", "stage");
  if (!models.empty())
    for (const ImplementationFigures& peer : models.front().peers)
      out += fmt::format(" {:>22}", fmt::format("cleave/{} (diff)", implementation_key(peer.implementation)));
  out += "\n";
  for (const ModelFigures& m : models)
    for (Stage s : kAllStages) {
      const StageFigures& mine = m.cleave.stage(s);
      if (mine.time.count == 0) continue;
      out += fmt::format("{:<14} {:<12}", m.model.key, stage_key(s));
      for (const ImplementationFigures& peer : m.peers) {
        const StageFigures& theirs = peer.stage(s);
        if (theirs.time.count == 0 || theirs.time.median_ms <= 0) {
          out += fmt::format(" {:>22}", "-");
          continue;
        }
        const std::string diff = theirs.relative_difference ? fmt::format("{:.1e}", *theirs.relative_difference) : "-";
        out += fmt::format(" {:>22}", fmt::format("{:.3f} ({})", mine.time.median_ms / theirs.time.median_ms, diff));
      }
      out += "\n";
    }
  return out;
}

std::string paper_table(const std::vector<ModelFigures>& models) {
  std::string out = fmt::format("{:<14} {:>14} {:>14} {:>14} {:>14} {:>14} {:>14}\n", "model", "paper vector", "cleave vector",
                                "paper value", "cleave value", "paper step", "cleave step");
  for (const ModelFigures& m : models) {
    if (!m.model.paper) continue;
    const PaperFigures& p = *m.model.paper;
    out += fmt::format("{:<14} {:>14.1f} {:>14} {:>14.1f} {:>14} {:>14.1f} {:>14}\n", m.model.key, p.ms_vector, ms_text(m.cleave.vector),
                       p.ms_value, ms_text(m.cleave.value), p.ms_step, ms_text(m.cleave.step));
  }
  return out;
}

}  // namespace cleave::bench
