// The studio's computation on the bare abdomen starts from the demo's settings (no equilibrium
// term, exact equilibration at the free vertices, rim and inner surface held), so the preview's
// round incisions open as in `cleave demo` (docs/stress-design.md: mean axis ratio 1.10, long axes
// along Langer's lines) also away from the control points; a case file keeps its own settings.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <functional>
#include <fstream>
#include <map>
#include <mutex>
#include <set>
#include <thread>
#include <unistd.h>

#include "cleave/pipeline/demo_case.hpp"
#include "studio/finite_message.hpp"
#include "studio/packed_array.hpp"
#include "studio/studio_compute.hpp"
#include "studio/studio_main.hpp"
#include "studio/studio_session.hpp"
#include "studio/wire_message.hpp"

namespace cleave::studio {
namespace {

using nlohmann::json;

std::filesystem::path fresh_folder(const std::string& name) {
  const auto dir = std::filesystem::temp_directory_path() / ("cleave-compute-test-" + name + "-" + std::to_string(::getpid()));
  std::filesystem::remove_all(dir);
  return dir;
}

const json kCoarseAbdomen = {{"source", "abdomen"}, {"resolution", {48, 16, 32}}};

/// Adds the strokes and control points of `cleave demo`'s design on the session's abdomen as
/// edits; returns that design (the case format's "design" section).
json add_demo_design(StudioSession& session) {
  const json design = abdomen_demo_case(session.model(), DemoStress::designed)["design"];
  for (const json& stroke : design["strokes"]) session.apply_edit({{"cmd", "add_stroke"}, {"points_mm", stroke["points"]}});
  for (const json& p : design["control_points"])
    session.apply_edit({{"cmd", "add_control_point"}, {"position_mm", p["position"]}, {"langer_kPa", p["langer_kPa"]},
                        {"cross_kPa", p["cross_kPa"]}});
  return design;
}

TEST(StudioCase, TheBareAbdomenGetsTheDemosSettingsFromTheSharedFunction) {
  const json c = bare_model_case(kCoarseAbdomen);
  StudioSession s(fresh_folder("bare"), c);
  const json demo = abdomen_demo_settings(s.model());
  EXPECT_EQ(c["design"], demo["design"]);
  EXPECT_EQ(c["simulation"], demo["simulation"]);
  EXPECT_EQ(c["design"]["weights"]["equilibrium"], 0.0);
  EXPECT_EQ(c["design"]["equilibrate"], true);
  EXPECT_EQ(c["design"]["equilibrium_support"], "simulation");
  EXPECT_EQ(bare_model_case({{"source", "plate"}, {"resolution", {8, 8, 2}}}),
            json({{"cleave_case", 1}, {"model", {{"source", "plate"}, {"resolution", {8, 8, 2}}}}}))
      << "other built-in models: the library's defaults";
}

TEST(StudioCase, ACaseFileKeepsItsOwnSettings) {
  const auto folder = fresh_folder("own");
  std::filesystem::create_directories(folder);
  const json own = {{"cleave_case", 1},
                    {"model", kCoarseAbdomen},
                    {"design", {{"strokes", json::array()}, {"control_points", {{{"position", {0, 0, 0}}, {"langer_kPa", 5}, {"cross_kPa", 1}}}},
                                {"weights", {{"equilibrium", 2.0}}}, {"equilibrate", false}}}};
  std::ofstream(folder / "own.json") << own.dump();
  const json c = *case_for_model_argument((folder / "own.json").string(), "");
  EXPECT_EQ(c["design"]["weights"]["equilibrium"], 2.0);
  EXPECT_EQ(c["design"]["equilibrate"], false);
  EXPECT_FALSE(c.contains("simulation"));
  const json bare = *case_for_model_argument("abdomen", "48x16x32");
  EXPECT_EQ(bare["design"]["equilibrium_support"], "simulation");
}

/// The messages a StudioCompute sends (from its worker thread), decoded: every one, or those of
/// one type.
struct MessageLog {
  explicit MessageLog(std::string type = {}) : only_type(std::move(type)) {}
  std::string only_type;  ///< empty: every message
  std::mutex mutex;
  std::vector<json> messages;
  std::vector<BroadcastKind> kinds;  ///< of each message kept
  std::map<std::string, std::set<BroadcastKind>> kinds_of_type;  ///< of every message sent
  StudioCompute::Send sender() {
    return [this](std::string text, BroadcastKind kind) {
      json message = wire_decoded(text);
      std::lock_guard lock(mutex);
      kinds_of_type[message["type"]].insert(kind);
      if (!only_type.empty() && message["type"] != only_type) return;
      messages.push_back(std::move(message));
      kinds.push_back(kind);
    };
  }
};

TEST(StudioCompute, PreviewIncisionsOpenAlongLangerAwayFromTheControlPoints) {
  StudioSession session(fresh_folder("preview"), bare_model_case(kCoarseAbdomen));
  const json demo = add_demo_design(session);
  MessageLog log;
  StudioCompute compute(session, log.sender());
  std::mutex& m = log.mutex;
  std::vector<json>& sent = log.messages;
  compute.design_changed(session.design(), session.seq());
  compute.wait_idle();
  std::lock_guard lock(m);
  ASSERT_FALSE(sent.empty());
  for (const json& message : sent) {
    EXPECT_NE(message["type"], "error") << message.dump().substr(0, 300);
    EXPECT_EQ(first_non_finite(message), std::nullopt);
  }
  const json& r = sent.back();
  ASSERT_EQ(r["type"], "result");
  EXPECT_FALSE(r.contains("design_error")) << r.dump().substr(0, 300);
  EXPECT_LT(r["equilibrium_residual"]["final"].get<double>(), 1e-8) << "exactly equilibrated at the free vertices";
  EXPECT_TRUE(r["timings_ms"].contains("equilibration"));

  // Control points at 0.3 and 0.7 of the width and length; incisions farther than 40 mm from all
  // of them must open too (with the least-squares equilibrium term they closed there).
  std::vector<Vec3> points;
  for (const json& p : demo["control_points"]) points.push_back(Vec3(p["position"][0], p["position"][1], p["position"][2]));
  const json& incisions = r["incisions"];
  ASSERT_GE(incisions.size(), 8u);
  int far = 0, far_open = 0, along = 0;
  double ratio_sum = 0;
  for (const json& i : incisions) {
    const Vec3 c(i["centre_mm"][0], i["centre_mm"][1], i["centre_mm"][2]);
    double nearest = 1e9;
    for (const Vec3& p : points) nearest = std::min(nearest, (c - p).norm());
    const double opening = i["opening_mm"];
    const double ratio = i["axis_ratio"];
    EXPECT_GT(opening, 0.0) << "every margin opens (the skin is in tension)";
    EXPECT_LT(opening, 5.0) << "an 8 to 17 mm incision does not gape by centimetres";
    EXPECT_GE(ratio, 1.0);
    EXPECT_LT(ratio, 1.3);
    ratio_sum += ratio;
    if (i.contains("langer_angle_deg") && i["langer_angle_deg"].get<double>() < 20) ++along;
    if (nearest > 40) {
      ++far;
      if (opening > 0.3) ++far_open;
    }
  }
  const double mean_ratio = ratio_sum / static_cast<double>(incisions.size());
  EXPECT_GT(mean_ratio, 1.03) << "round incisions open into ellipses (demo: 1.10)";
  EXPECT_LT(mean_ratio, 1.2);
  EXPECT_GE(far, 3);
  EXPECT_EQ(far_open, far) << "incisions away from the control points open by more than 0.3 mm";
  EXPECT_GE(along, static_cast<int>(incisions.size()) * 3 / 4) << "long axes along Langer's lines";
}

TEST(StudioCompute, AResultOnTheSameSurfaceLeavesItsTrianglesOutAndANewClientGetsThemAll) {
  StudioSession session(fresh_folder("lean"), bare_model_case(kCoarseAbdomen));
  const json demo = abdomen_demo_case(session.model(), DemoStress::designed);
  MessageLog log{"result"};
  StudioCompute compute(session, log.sender());
  std::mutex& m = log.mutex;
  std::vector<json>& results = log.messages;
  const auto edit = [&](const json& e) {
    session.apply_edit(e);
    compute.design_changed(session.design(), session.seq());
    compute.wait_idle();
  };
  edit({{"cmd", "add_stroke"}, {"points_mm", demo["design"]["strokes"][0]["points"]}});
  edit({{"cmd", "add_stroke"}, {"points_mm", demo["design"]["strokes"][1]["points"]}});
  const json& cut = demo["cuts"][0];
  edit({{"cmd", "add_cut"}, {"kind", "scalpel"}, {"path_mm", cut["path_mm"]}, {"depth_mm", cut["depth_mm"]}});
  edit({{"cmd", "undo"}});
  compute.wait_idle();
  std::lock_guard lock(m);  // the worker is idle: nothing sends any more
  ASSERT_EQ(results.size(), 4u);
  const json& first = results[0]["surface"];
  const json& second = results[1]["surface"];
  const json& third = results[2]["surface"];
  ASSERT_TRUE(first.contains("triangles"));
  EXPECT_FALSE(second.contains("triangles")) << "a stroke does not change the surface: its triangles are not sent again";
  EXPECT_EQ(second["id"], first["id"]);
  ASSERT_TRUE(third.contains("triangles")) << "a cut makes a new surface";
  EXPECT_NE(third["id"], first["id"]);
  // What each may replace in a slow client's queue (broadcast_kind.hpp): only a result that
  // carries its triangles may stand in for one that carried them.
  EXPECT_EQ(log.kinds, (std::vector<BroadcastKind>{BroadcastKind::full_result, BroadcastKind::partial_result,
                                                   BroadcastKind::full_result, BroadcastKind::full_result}));

  // The packed arrays describe one mesh: every index names a vertex, every field has one value per vertex.
  const std::vector<float> positions = unpacked_floats(second["positions_mm"]);
  const std::vector<std::uint32_t> triangles = unpacked_indices(first["triangles"]);
  ASSERT_EQ(positions.size() % 3, 0u);
  ASSERT_EQ(triangles.size() % 3, 0u);
  ASSERT_GE(triangles.size(), 3000u);
  const auto vertices = static_cast<std::uint32_t>(positions.size() / 3);
  EXPECT_LT(*std::max_element(triangles.begin(), triangles.end()), vertices);
  EXPECT_TRUE(std::all_of(positions.begin(), positions.end(), [](float v) { return std::isfinite(v); }));
  const std::vector<float> direction = unpacked_floats(results[1]["fields"]["direction"]);
  ASSERT_EQ(direction.size(), positions.size());
  for (std::size_t v = 0; v < vertices; ++v) {
    const double length = std::hypot(direction[3 * v], direction[3 * v + 1], direction[3 * v + 2]);
    EXPECT_NEAR(length, 1.0, 1e-5) << "a unit Langer direction at surface vertex " << v;
    if (std::abs(length - 1.0) > 1e-5) break;
  }

  // A client that connects now gets the latest result (the undo's) with its triangles.
  const std::vector<std::string> welcome = compute.welcome_messages();
  ASSERT_EQ(welcome.size(), 1u);
  EXPECT_TRUE(is_binary_wire(welcome[0])) << "a result with packed arrays travels as a binary message";
  const json latest = wire_decoded(welcome[0]);
  EXPECT_EQ(latest["seq"], results[3]["seq"]);
  ASSERT_TRUE(results[3]["surface"].contains("triangles")) << "undoing the cut returns to a surface the clients do not hold";
  EXPECT_NE(results[3]["surface"]["id"], first["id"]) << "rebuilt, so named anew";
  ASSERT_TRUE(latest["surface"].contains("triangles")) << "the latest result keeps its triangles for new clients";
  EXPECT_EQ(unpacked_indices(latest["surface"]["triangles"]), triangles) << "the uncut surface again";
}

// The cut faces' depths belong to the surface like its triangles: a result on the surface the
// clients hold leaves them out (194 KB of 2.55 MB at 45k cells), a new client gets them in full,
// and they are the same numbers.
TEST(StudioCompute, AResultOnTheSameSurfaceLeavesItsCutFaceDepthsOut) {
  StudioSession session(fresh_folder("lean-depth"), bare_model_case(kCoarseAbdomen));
  add_demo_design(session);
  MessageLog log{"result"};
  StudioCompute compute(session, log.sender());
  compute.design_changed(session.design(), session.seq());
  compute.wait_idle();
  const int point = session.design().control_points.front().id;
  session.apply_edit({{"cmd", "set_control_point"}, {"id", point}, {"langer_kPa", 25.0}});
  compute.design_changed(session.design(), session.seq());
  compute.wait_idle();
  std::lock_guard lock(log.mutex);
  ASSERT_EQ(log.messages.size(), 2u);
  const json& first = log.messages[0];
  const json& second = log.messages[1];
  ASSERT_TRUE(first["fields"].contains("cut_depth")) << "the incision preview's cut faces";
  EXPECT_EQ(second["surface"]["id"], first["surface"]["id"]) << "a value edit keeps the surface";
  EXPECT_FALSE(second["fields"].contains("cut_depth")) << "the clients hold this surface's depths";
  EXPECT_TRUE(second["fields"].contains("traction_kPa")) << "the tractions follow the stress: sent";
  const std::vector<std::string> welcome = compute.welcome_messages();
  ASSERT_EQ(welcome.size(), 1u);
  const json latest = wire_decoded(welcome[0]);
  EXPECT_EQ(latest["seq"], second["seq"]);
  ASSERT_TRUE(latest["fields"].contains("cut_depth")) << "a new client gets the depths with the surface";
  EXPECT_EQ(unpacked_floats(latest["fields"]["cut_depth"]), unpacked_floats(first["fields"]["cut_depth"]));
}

// The incision margins are sampled once per cut body (studio_compute.cpp) and reused for every
// edit's displacement: after a cut they must be those of the new body, so a session that cut late
// measures what a session that had the cut from the start measures.
TEST(StudioCompute, MeasurementsAfterACutEqualThoseOfASessionThatStartedWithIt) {
  const json demo = [] {
    StudioSession probe(fresh_folder("measure-probe"), bare_model_case(kCoarseAbdomen));
    return abdomen_demo_case(probe.model(), DemoStress::designed);
  }();
  const json& design = demo["design"];
  // A scalpel cut along the first stroke: across the whole width, past several incisions' rims.
  const json add_cut = {{"cmd", "add_cut"}, {"kind", "scalpel"}, {"path_mm", design["strokes"][0]["points"]}, {"depth_mm", 5.0}};
  const auto last_result = [&](const std::string& name, bool cut_first) {
    StudioSession session(fresh_folder(name), bare_model_case(kCoarseAbdomen));
    MessageLog log{"result"};
    StudioCompute compute(session, log.sender());
    const auto edit = [&](const json& e, bool recompute) {
      session.apply_edit(e);
      if (!recompute) return;
      compute.design_changed(session.design(), session.seq());
      compute.wait_idle();
    };
    if (cut_first) edit(add_cut, false);
    edit({{"cmd", "add_stroke"}, {"points_mm", design["strokes"][0]["points"]}}, !cut_first);
    const json& p = design["control_points"][0];
    edit({{"cmd", "add_control_point"}, {"position_mm", p["position"]}, {"langer_kPa", 20}, {"cross_kPa", 10}}, !cut_first);
    if (!cut_first) edit(add_cut, false);
    compute.design_changed(session.design(), session.seq());
    compute.wait_idle();
    std::lock_guard lock(log.mutex);
    // The wound opening's frames lead up to the result: a newer result never moves ahead of one.
    EXPECT_EQ(log.kinds_of_type["frame"], std::set<BroadcastKind>{BroadcastKind::frame});
    return log.messages.back();
  };
  const json late = last_result("measure-late", false);
  const json early = last_result("measure-early", true);
  ASSERT_FALSE(early["incisions"].empty());
  ASSERT_EQ(late["incisions"].size(), early["incisions"].size()) << "the cut removes the incisions it crosses";
  for (std::size_t i = 0; i < early["incisions"].size(); ++i) {
    EXPECT_NEAR(late["incisions"][i]["opening_mm"].get<double>(), early["incisions"][i]["opening_mm"].get<double>(), 1e-6) << i;
    EXPECT_NEAR(late["incisions"][i]["axis_ratio"].get<double>(), early["incisions"][i]["axis_ratio"].get<double>(), 1e-6) << i;
  }
  // The cut keeps the designed stress but changes the surface: the residual display remembered
  // for that stress on the uncut surface must not be reused (one value per vertex of this surface).
  const std::size_t surface_vertices = unpacked_floats(late["surface"]["positions_mm"]).size() / 3;
  EXPECT_EQ(unpacked_floats(late["fields"]["residual_kPa"]).size(), surface_vertices);
  EXPECT_EQ(unpacked_floats(late["fields"]["residual_kPa"]), unpacked_floats(early["fields"]["residual_kPa"]));
  ASSERT_EQ(late["wounds"].size(), 1u) << (late.contains("cut_error") ? late["cut_error"].dump() : "");
  EXPECT_NEAR(late["wounds"][0]["width_mm"].get<double>(), early["wounds"][0]["width_mm"].get<double>(), 1e-6);
}

// A stroke dragged over fresh cells: the picture is drawn from the equilibration's provisional
// stress, then a "design_final" message of the same edit brings the final design's residual
// display and residual; a client that connects afterwards gets the final one.
TEST(StudioCompute, APictureFromAProvisionalStressIsFollowedByTheFinalDesign) {
  // The free body (equilibrium at every vertex, as the bench's scenario): its thin shell's soft
  // modes make an edit over fresh cells take a second step (with the rim held, one suffices).
  json free_body = bare_model_case(kCoarseAbdomen);
  free_body["design"]["equilibrium_support"] = "none";
  StudioSession session(fresh_folder("provisional"), free_body);
  add_demo_design(session);
  MessageLog log;
  StudioCompute compute(session, log.sender());
  std::mutex& m = log.mutex;
  std::vector<json>& sent = log.messages;
  const auto recompute = [&] {
    compute.design_changed(session.design(), session.seq());
    compute.wait_idle();
  };
  recompute();
  const double h = session.model().volume.grid().cell_size_mm;
  const std::uint64_t first_stroke = session.design().strokes.front().id;
  for (int drag = 0; drag < 4; ++drag) {
    session.apply_edit({{"cmd", "move_stroke"}, {"id", first_stroke}, {"offset_mm", {0.0, 0.0, h}}});
    recompute();
  }
  std::lock_guard lock(m);
  int provisional = 0;
  json last_final;
  for (std::size_t i = 0; i < sent.size(); ++i) {
    const json& r = sent[i];
    ASSERT_NE(r["type"], "error") << r.dump().substr(0, 300);
    EXPECT_EQ(first_non_finite(r), std::nullopt);
    if (r["type"] == "design_final") {
      ADD_FAILURE() << "a design_final without the provisional result before it";
      continue;
    }
    if (r["type"] != "result" || !r["equilibrium_residual"].contains("provisional")) continue;
    ++provisional;
    while (i + 1 < sent.size() && sent[i + 1]["type"] == "progress") ++i;  // a heartbeat may come between
    ASSERT_LT(i + 1, sent.size());
    const json& f = sent[++i];
    ASSERT_EQ(f["type"], "design_final");
    EXPECT_EQ(f["seq"], r["seq"]);
    EXPECT_EQ(f["generation"], r["generation"]);
    EXPECT_LT(f["equilibrium_residual"]["final"].get<double>(), r["equilibrium_residual"]["final"].get<double>());
    EXPECT_LT(f["equilibrium_residual"]["final"].get<double>(), 1e-8);
    EXPECT_EQ(f["equilibrium_residual"]["designed"], r["equilibrium_residual"]["designed"]);
    EXPECT_GE(f["equilibration_iterations"].get<int>(), 2);
    EXPECT_TRUE(f["timings_ms"].contains("equilibration_completion"));
    const std::vector<float> before = unpacked_floats(r["fields"]["residual_kPa"]);
    const std::vector<float> after = unpacked_floats(f["fields"]["residual_kPa"]);
    ASSERT_EQ(after.size(), before.size()) << "one value per vertex of the same surface";
    EXPECT_NE(after, before);
    last_final = f;
  }
  ASSERT_GE(provisional, 1) << "no drag over fresh cells stopped for the picture";
  const auto last = std::find_if(sent.rbegin(), sent.rend(), [](const json& r) { return r["type"] != "progress"; });
  const json& latest = *last;
  ASSERT_EQ(latest["type"], "design_final") << "the last drag's equilibration completes after its picture";
  const std::vector<std::string> welcome = compute.welcome_messages();
  ASSERT_EQ(welcome.size(), 1u);
  const json joined = wire_decoded(welcome[0]);
  EXPECT_EQ(joined["seq"], latest["seq"]);
  EXPECT_EQ(joined["equilibrium_residual"], latest["equilibrium_residual"]) << "a new client gets the final design";
  EXPECT_EQ(unpacked_floats(joined["fields"]["residual_kPa"]), unpacked_floats(latest["fields"]["residual_kPa"]));
}

// A stroke or a control point dragged off the surface fails the design's validation: the result
// names the error and shows the last valid design (its fields, incisions and the same cut model),
// and the designer is kept, so moving back is an edit answered from memory, not a new designer
// (7-14 s at 45k cells) and a new cut model (whose factor takes 15-25 s).
TEST(StudioCompute, AnEditOffTheSurfaceShowsTheLastValidDesignAndKeepsTheDesigner) {
  StudioSession session(fresh_folder("off-surface"), bare_model_case(kCoarseAbdomen));
  add_demo_design(session);
  MessageLog log{"result"};
  StudioCompute compute(session, log.sender());
  const auto edit = [&](const json& e) {
    if (!e.is_null()) session.apply_edit(e);
    compute.design_changed(session.design(), session.seq());
    compute.wait_idle();
    std::lock_guard lock(log.mutex);
    return log.messages.back();
  };
  const json valid = edit(nullptr);
  ASSERT_FALSE(valid.contains("design_error"));
  ASSERT_FALSE(valid["incisions"].empty());
  const int stroke = session.design().strokes.front().id;
  const int point = session.design().control_points.front().id;
  const Vec3 at = session.design().control_points.front().position_mm;
  const auto expect_last_valid = [&](const json& r, const std::string& what) {
    SCOPED_TRACE(what);
    ASSERT_TRUE(r.contains("design_error"));
    const std::string error = r["design_error"];
    EXPECT_NE(error.find("from the body surface"), std::string::npos) << error;
    EXPECT_NE(error.find("; the last valid design is shown"), std::string::npos) << error;
    EXPECT_EQ(r["surface"]["id"], valid["surface"]["id"]) << "the same cut model: no re-cut";
    EXPECT_EQ(r["incisions"], valid["incisions"]);
    EXPECT_EQ(unpacked_floats(r["fields"]["langer_kPa"]), unpacked_floats(valid["fields"]["langer_kPa"]));
    EXPECT_EQ(unpacked_floats(r["fields"]["direction"]), unpacked_floats(valid["fields"]["direction"]));
    EXPECT_EQ(r["equilibrium_residual"], valid["equilibrium_residual"]);
  };
  expect_last_valid(edit({{"cmd", "move_stroke"}, {"id", stroke}, {"offset_mm", {0.0, 60.0, 0.0}}}), "a stroke off the surface");
  const json back = edit({{"cmd", "move_stroke"}, {"id", stroke}, {"offset_mm", {0.0, -60.0, 0.0}}});
  EXPECT_FALSE(back.contains("design_error"));
  EXPECT_EQ(back["surface"]["id"], valid["surface"]["id"]);
  EXPECT_EQ(back["timings_ms"]["directions"], 0.0) << "the kept designer recalls the valid design";
  EXPECT_EQ(back["incisions"], valid["incisions"]);
  expect_last_valid(edit({{"cmd", "set_control_point"}, {"id", point}, {"position_mm", {at.x(), at.y() + 60.0, at.z()}}}),
                    "a control point off the surface");
}

TEST(StudioCompute, ANewCutModelIsSolvedByTheMultigridUntilItsFactorIsReadyAndBothAgree) {
  StudioSession session(fresh_folder("handoff"), bare_model_case(kCoarseAbdomen));
  const json demo = abdomen_demo_case(session.model(), DemoStress::designed)["design"];
  session.apply_edit({{"cmd", "add_stroke"}, {"points_mm", demo["strokes"][0]["points"]}});
  const json& p = demo["control_points"][0];
  session.apply_edit({{"cmd", "add_control_point"}, {"position_mm", p["position"]}, {"langer_kPa", 20}, {"cross_kPa", 10}});
  MessageLog log{"result"};
  StudioCompute compute(session, log.sender());
  std::mutex& m = log.mutex;
  std::vector<json>& results = log.messages;
  const auto latest = [&] {
    compute.design_changed(session.design(), session.seq());
    compute.wait_idle();
    std::lock_guard lock(m);
    return results.back();
  };
  const json first = latest();
  ASSERT_EQ(first["statics_solver"], "multigrid") << "a new cut model: the multigrid answers at once";
  ASSERT_FALSE(first["incisions"].empty());
  // The same design again until the factor made meanwhile is taken (it is made on its own thread).
  json again;
  for (int attempt = 0; attempt < 200; ++attempt) {
    again = latest();
    if (again["statics_solver"] == "cholmod") break;
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  ASSERT_EQ(again["statics_solver"], "cholmod");
  ASSERT_EQ(again["incisions"].size(), first["incisions"].size());
  for (std::size_t i = 0; i < first["incisions"].size(); ++i) {
    EXPECT_NEAR(again["incisions"][i]["opening_mm"].get<double>(), first["incisions"][i]["opening_mm"].get<double>(), 1e-4)
        << "incision " << i << ": the multigrid's and the factor's statics agree";
    EXPECT_NEAR(again["incisions"][i]["axis_ratio"].get<double>(), first["incisions"][i]["axis_ratio"].get<double>(), 1e-4);
  }
}

}  // namespace
}  // namespace cleave::studio
