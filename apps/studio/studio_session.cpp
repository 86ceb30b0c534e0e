#include "studio/studio_session.hpp"

#include <fmt/format.h>

#include "cleave/core/error.hpp"
#include "cleave/io/atomic_file.hpp"
#include "cleave/io/case_file.hpp"
#include "cleave/pipeline/demo_case.hpp"
#include "studio/design_edit.hpp"
#include "studio/path_safety.hpp"
#include "studio/session_case.hpp"

namespace cleave::studio {
namespace {

constexpr const char* kSessionFile = "session.json";
constexpr const char* kJournalFile = "journal.jsonl";
constexpr std::uintmax_t kMaxCaseBytes = 64u << 20;

std::unique_ptr<TissueModel> load_model(const CaseFile& c) {
  LabelVolume labels = load_model_source(c.model_source, c.model_options);
  return std::make_unique<TissueModel>(make_tissue_model(c.model_source, std::move(labels), c.materials));
}

}  // namespace

nlohmann::json bare_model_case(const nlohmann::json& model) {
  nlohmann::json doc = {{"cleave_case", 1}, {"model", model}};
  if (model.value("source", "") != "abdomen") return doc;
  const CaseFile parsed = parse_case_text(doc.dump(), "the abdomen", std::filesystem::current_path());
  const std::unique_ptr<TissueModel> abdomen = load_model(parsed);
  const nlohmann::json settings = abdomen_demo_settings(*abdomen);
  doc["design"] = settings.at("design");
  doc["simulation"] = settings.at("simulation");
  return doc;
}

nlohmann::json default_session_case() {
  return bare_model_case({{"source", "abdomen"}, {"resolution", {63, 21, 42}}});
}

StudioSession::StudioSession(std::filesystem::path folder, std::optional<nlohmann::json> case_document)
    : folder_(std::move(folder)) {
  std::error_code ec;
  std::filesystem::create_directories(folder_, ec);
  if (ec || !std::filesystem::is_directory(folder_))
    throw InputError(fmt::format("--session '{}': cannot create the session folder: {}", folder_.string(), ec.message()));
  const auto session_file = folder_ / kSessionFile;
  const auto journal_file = folder_ / kJournalFile;
  std::optional<nlohmann::json> stored;
  if (std::filesystem::exists(session_file)) {
    const nlohmann::json meta = parse_json_text(read_file(session_file, kMaxCaseBytes), session_file.string());
    if (!meta.is_object() || !meta.contains("case") || !meta["case"].is_object())
      throw InputError(fmt::format("{}: expected {{\"cleave_session\":1, \"case\":{{...}}}}", session_file.string()));
    stored = meta["case"];
  }
  const bool has_edits = std::filesystem::exists(journal_file) && std::filesystem::file_size(journal_file) > 0;
  if (case_document && stored && has_edits && (*case_document)["model"] != (*stored)["model"])
    throw InputError(fmt::format("--session '{}' holds a session on model {}; open it without a MODEL argument or "
                                 "choose another --session folder for {}",
                                 folder_.string(), (*stored)["model"].dump(), (*case_document)["model"].dump()));
  if (case_document && (!stored || !has_edits)) {
    case_ = *case_document;
    write_file_atomically(session_file, nlohmann::json{{"cleave_session", 1}, {"case", case_}}.dump(2) + "\n");
  } else if (stored) {
    case_ = *stored;
  } else {
    case_ = default_session_case();
    write_file_atomically(session_file, nlohmann::json{{"cleave_session", 1}, {"case", case_}}.dump(2) + "\n");
  }
  case_file_ = std::make_unique<CaseFile>(parse_case_text(case_.dump(), kSessionFile, folder_));
  model_ = load_model(*case_file_);
  history_ = EditHistory(design_from_case(case_, kSessionFile, 1));
  journal_ = std::make_unique<SessionJournal>(journal_file);
  for (const nlohmann::json& entry : journal_->entries())
    apply_in_memory(entry["edit"], fmt::format("{} seq {}", journal_file.string(), entry["seq"].get<std::uint64_t>()));
}

void StudioSession::apply_in_memory(const nlohmann::json& edit, const std::string& where) {
  const nlohmann::json* cmd = edit.is_object() ? json_find(edit, "cmd") : nullptr;
  if (cmd && *cmd == "undo") history_.undo();
  else if (cmd && *cmd == "redo") history_.redo();
  else history_.push(apply_design_edit(history_.current(), edit, where));
}

std::uint64_t StudioSession::apply_edit(const nlohmann::json& edit) {
  // Validate first, then make it durable, then change the state: a failed edit changes nothing.
  const nlohmann::json* cmd = edit.is_object() ? json_find(edit, "cmd") : nullptr;
  if (cmd && *cmd == "undo") {
    if (!history_.can_undo()) throw InputError("undo: nothing to undo");
    const std::uint64_t seq = journal_->append(edit);
    history_.undo();
    return seq;
  }
  if (cmd && *cmd == "redo") {
    if (!history_.can_redo()) throw InputError("redo: nothing to redo");
    const std::uint64_t seq = journal_->append(edit);
    history_.redo();
    return seq;
  }
  DesignState next = apply_design_edit(history_.current(), edit, "message");
  const std::uint64_t seq = journal_->append(edit);
  history_.push(std::move(next));
  return seq;
}

std::filesystem::path StudioSession::save_case(const std::string& file_name) const {
  const auto file = require_inside(folder_, file_name, "save: file");
  if (file.extension() != ".json") throw InputError(fmt::format("save: file '{}' must end in .json", file_name));
  write_file_atomically(file, case_with_design(case_, design()).dump(2) + "\n");
  return file;
}

nlohmann::json StudioSession::load_case_edit(const std::string& file_name) const {
  const auto file = require_inside(folder_, file_name, "load: file");
  if (!std::filesystem::is_regular_file(file))
    throw InputError(fmt::format("load: file '{}' does not exist in the session folder", file_name));
  const CaseFile loaded = parse_case_text(read_file(file, kMaxCaseBytes), file_name, folder_);
  const CaseFile mine = parse_case_text(case_.dump(), kSessionFile, folder_);
  if (loaded.model_source != mine.model_source || loaded.document.value("model", nlohmann::json{}) != case_["model"])
    throw InputError(fmt::format("load: {} is a case on model {}; this session's model is {} (start the studio on that "
                                 "case to open it)",
                                 file_name, loaded.document["model"].dump(), case_["model"].dump()));
  const DesignState design = design_from_case(loaded.document, file_name, history_.current().next_id);
  return {{"cmd", "replace_design"}, {"design", to_json(design)}};
}

nlohmann::json StudioSession::state_message() const {
  return {{"type", "state"},
          {"seq", seq()},
          {"design", to_json(design())},
          {"can_undo", history_.can_undo()},
          {"can_redo", history_.can_redo()},
          {"model", case_["model"]}};
}

}  // namespace cleave::studio
