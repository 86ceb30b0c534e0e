// Sessions and messages: edits with undo/redo, replay after a restart, save/load round trips,
// exact error replies, and the worker that drops stale work.
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <filesystem>
#include <mutex>
#include <string>
#include <thread>
#include <utility>
#include <vector>
#include <unistd.h>

#include "cleave/core/error.hpp"
#include "studio/design_limits.hpp"
#include "studio/field_worker.hpp"
#include "studio/message_handler.hpp"
#include "studio/studio_session.hpp"

namespace cleave::studio {
namespace {

using nlohmann::json;

std::filesystem::path fresh_folder(const std::string& name) {
  const auto dir = std::filesystem::temp_directory_path() / ("cleave-session-test-" + name + "-" + std::to_string(::getpid()));
  std::filesystem::remove_all(dir);
  return dir;
}

json small_plate() { return {{"cleave_case", 1}, {"model", {{"source", "plate"}, {"resolution", {8, 8, 2}}}}}; }

json stroke(double y) { return {{"cmd", "add_stroke"}, {"points_mm", {{0, y, 0}, {5, y, 0}, {10, y, 1}}}}; }

json reply(StudioSession& s, const json& message) { return handle_message(s, message.dump(), nullptr).reply; }

TEST(StudioSession, EditsUndoRedoAndIdsNeverReused) {
  StudioSession s(fresh_folder("edits"), small_plate());
  EXPECT_EQ(s.apply_edit(stroke(1)), 1u);
  EXPECT_EQ(s.apply_edit(stroke(2)), 2u);
  ASSERT_EQ(s.design().strokes.size(), 2u);
  EXPECT_EQ(s.design().strokes[0].id, 1);
  EXPECT_EQ(s.design().strokes[1].id, 2);
  s.apply_edit({{"cmd", "undo"}});
  EXPECT_EQ(s.design().strokes.size(), 1u);
  s.apply_edit(stroke(3));  // drops the redo branch; must not reuse id 2
  ASSERT_EQ(s.design().strokes.size(), 2u);
  EXPECT_EQ(s.design().strokes[1].id, 3);
  EXPECT_FALSE(s.history().can_redo());
  s.apply_edit({{"cmd", "move_stroke"}, {"id", 3}, {"offset_mm", {1, 0, 0}}});
  EXPECT_DOUBLE_EQ(s.design().strokes[1].points_mm[2].x(), 11.0);
  s.apply_edit({{"cmd", "undo"}});
  EXPECT_DOUBLE_EQ(s.design().strokes[1].points_mm[2].x(), 10.0);
  s.apply_edit({{"cmd", "redo"}});
  EXPECT_DOUBLE_EQ(s.design().strokes[1].points_mm[2].x(), 11.0);
  EXPECT_EQ(s.seq(), 7u);
}

TEST(StudioSession, RestartReplaysTheJournalToTheSameState) {
  const auto folder = fresh_folder("replay");
  DesignState before;
  std::uint64_t seq = 0;
  {
    StudioSession s(folder, small_plate());
    s.apply_edit(stroke(1));
    s.apply_edit({{"cmd", "add_control_point"}, {"position_mm", {4, 4, 1}}, {"langer_kPa", 25}});
    s.apply_edit({{"cmd", "set_control_point"}, {"id", 2}, {"cross_kPa", 7.5}});
    s.apply_edit({{"cmd", "add_cut"}, {"kind", "flap"}, {"path_mm", {{1, 1, 1}, {6, 1, 1}, {6, 6, 1}}}, {"depth_mm", 2}});
    s.apply_edit(stroke(2));
    s.apply_edit({{"cmd", "undo"}});
    before = s.design();
    seq = s.seq();
  }
  StudioSession again(folder, std::nullopt);  // no model argument: the folder's session
  EXPECT_EQ(again.seq(), seq);
  EXPECT_EQ(to_json(again.design()), to_json(before));
  EXPECT_EQ(again.design().control_points[0].cross_kPa, 7.5);
  EXPECT_EQ(again.design().cuts[0].kind, CutKind::flap);
  EXPECT_TRUE(again.history().can_redo()) << "the undone stroke can still be redone after a restart";
}

TEST(StudioSession, AnotherModelOnAFolderWithEditsIsRefused) {
  const auto folder = fresh_folder("model");
  {
    StudioSession s(folder, small_plate());
    s.apply_edit(stroke(1));
  }
  json other = small_plate();
  other["model"]["resolution"] = {6, 6, 2};
  EXPECT_THROW(StudioSession(folder, other), InputError);
}

TEST(StudioSession, SaveAndLoadRoundTripTheDesign) {
  StudioSession s(fresh_folder("save"), small_plate());
  s.apply_edit(stroke(1));
  s.apply_edit({{"cmd", "add_control_point"}, {"position_mm", {4, 4, 1}}, {"langer_kPa", 18}, {"cross_kPa", 9}});
  const DesignState saved = s.design();
  EXPECT_EQ(reply(s, {{"cmd", "save"}, {"file", "a.json"}})["type"], "saved");
  s.apply_edit({{"cmd", "delete_stroke"}, {"id", 1}});
  EXPECT_EQ(reply(s, {{"cmd", "load"}, {"file", "a.json"}})["type"], "ack");
  ASSERT_EQ(s.design().strokes.size(), 1u);
  EXPECT_EQ(s.design().strokes[0].points_mm, saved.strokes[0].points_mm);
  EXPECT_EQ(s.design().control_points[0].langer_kPa, 18);
  EXPECT_GT(s.design().strokes[0].id, 2) << "loaded items get fresh ids";
  s.apply_edit({{"cmd", "undo"}});
  EXPECT_TRUE(s.design().strokes.empty()) << "loading is one undoable edit";
}

TEST(MessageHandler, ErrorsAreOneLineAndLeaveTheSessionUnchanged) {
  StudioSession s(fresh_folder("errors"), small_plate());
  s.apply_edit(stroke(1));
  const json before = s.state_message();
  const auto error_of = [&](const std::string& text) {
    const MessageOutcome out = handle_message(s, text, nullptr);
    EXPECT_EQ(out.reply["type"], "error") << text;
    EXPECT_FALSE(out.design_changed);
    return out.reply.value("message", std::string());
  };
  EXPECT_EQ(error_of(R"({"cmd":"fly","req":7})"),
            "unknown command 'fly'; expected one of hello, get_state, ping, undo, redo, save, load, export, add_stroke, "
            "move_stroke, delete_stroke, add_control_point, set_control_point, delete_control_point, add_cut, delete_cut, "
            "reset_cuts");
  EXPECT_EQ(error_of(R"({"cmd":"add_stroke","points_mm":[[0,0,0]]})"),
            "message: /points_mm is 1; expected an array of 2 to 4096 points [x, y, z] in mm");
  EXPECT_EQ(error_of(R"({"cmd":"delete_stroke","id":99})"), "message: no stroke with id 99");
  EXPECT_EQ(error_of(R"({"cmd":"add_control_point","position_mm":[0,0,0],"langer_kPa":1e9})"),
            "message: /langer_kPa is 1000000000.0; expected an eigenvalue in kPa");
  EXPECT_EQ(error_of(R"({"cmd":"add_cut","path_mm":[[0,0,0],[1,0,0]],"depth_mm":-1})"),
            "message: /depth_mm is -1; expected a depth in mm");
  EXPECT_EQ(error_of(R"([1,2])"), "message: expected a JSON object {\"cmd\": ...}");
  EXPECT_NE(error_of("{oops").find("message: invalid JSON at byte 2"), std::string::npos);
  EXPECT_EQ(error_of(std::string(kMaxMessageBytes + 1, ' ')), "message of 4194305 bytes is over the limit of 4194304 bytes");
  EXPECT_EQ(error_of(R"({"cmd":"save","file":"../../etc/x.json"})"),
            "save: file '../../etc/x.json' is outside the session folder; expected a file name such as design.json");
  EXPECT_EQ(error_of(R"({"cmd":"export","format":"stl","file":"a.stl"})"),
            "export: /format is \"stl\"; expected \"vtu\", \"ply\" or \"gltf\"");
  EXPECT_EQ(error_of(R"({"cmd":"redo"})"), "redo: nothing to redo");
  EXPECT_EQ(s.state_message(), before);
  const json r = reply(s, {{"cmd", "ping"}, {"req", "abc"}});
  EXPECT_EQ(r["type"], "pong");
  EXPECT_EQ(r["req"], "abc");
}

TEST(FieldWorker, NewerJobsSupersedeOlderOnesAndOnlyCurrentResultsArePublished) {
  std::mutex m;
  std::vector<std::uint64_t> published;
  std::atomic<bool> release{false}, started{false};
  FieldWorker worker([&](FieldWorker::Result r) {
    std::lock_guard lock(m);
    published.push_back(r.generation);
  });
  // Job 1 blocks until released; jobs 2..9 queue up behind it and replace each other.
  worker.submit([&](const FieldWorker::Context& ctx) {
    started = true;
    while (!release.load()) std::this_thread::sleep_for(std::chrono::milliseconds(1));
    return json{{"type", "result"}, {"g", ctx.generation}};
  });
  // wait until job 1 is in flight (a fixed sleep failed on a loaded machine)
  while (!started.load()) std::this_thread::sleep_for(std::chrono::milliseconds(1));
  std::uint64_t last = 0;
  for (int i = 0; i < 8; ++i)
    last = worker.submit([](const FieldWorker::Context& ctx) { return json{{"type", "result"}, {"g", ctx.generation}}; });
  release = true;
  worker.wait_idle();
  EXPECT_EQ(last, 9u);
  EXPECT_EQ(worker.jobs_started(), 2u) << "the job in flight and the newest one; none of the stale ones";
  EXPECT_EQ(worker.jobs_skipped(), 7u) << "jobs 2 to 8, each replaced in the queue by the next";
  EXPECT_EQ(worker.jobs_submitted(), 9u);
  ASSERT_EQ(published.size(), 1u) << "the superseded job's result is discarded";
  EXPECT_EQ(published[0], 9u);
}

// JobThread::caller (what `cleave studio` uses, so that its jobs allocate from glibc's main heap):
// the jobs run on the thread that calls run_jobs(), which returns once another thread calls
// stop(); the job in flight then is superseded and its result dropped. A worker with its own
// thread refuses run_jobs().
TEST(FieldWorker, OnTheCallersThreadJobsRunThereUntilStopped) {
  std::mutex m;
  std::vector<std::uint64_t> published;
  FieldWorker worker(
      [&](FieldWorker::Result r) {
        std::lock_guard lock(m);
        published.push_back(r.generation);
      },
      {}, FieldWorker::JobThread::caller);
  const std::thread::id caller = std::this_thread::get_id();
  std::atomic<int> on_caller{0}, elsewhere{0};
  std::atomic<bool> second_started{false};
  worker.submit([&](const FieldWorker::Context& ctx) {
    (std::this_thread::get_id() == caller ? on_caller : elsewhere).fetch_add(1);
    return json{{"type", "result"}, {"g", ctx.generation}};
  });
  std::thread stopper([&] {
    // The first job's result, then a second job that runs until stop() supersedes it.
    for (;;) {
      {
        std::lock_guard lock(m);
        if (!published.empty()) break;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
    }
    worker.submit([&](const FieldWorker::Context& ctx) {
      (std::this_thread::get_id() == caller ? on_caller : elsewhere).fetch_add(1);
      second_started = true;
      while (!ctx.superseded()) std::this_thread::sleep_for(std::chrono::milliseconds(1));
      return json{{"type", "result"}, {"g", ctx.generation}};
    });
    while (!second_started.load()) std::this_thread::sleep_for(std::chrono::milliseconds(1));
    worker.stop();
  });
  worker.run_jobs();  // returns after stop()
  stopper.join();
  EXPECT_EQ(on_caller.load(), 2);
  EXPECT_EQ(elsewhere.load(), 0);
  ASSERT_EQ(published.size(), 1u) << "the job that stop() superseded publishes nothing";
  EXPECT_EQ(published[0], 1u);
  worker.submit([](const FieldWorker::Context&) { return json{{"type", "result"}}; });
  EXPECT_EQ(worker.jobs_started(), 2u) << "no job starts after stop()";

  FieldWorker own([](FieldWorker::Result) {});
  try {
    own.run_jobs();
    ADD_FAILURE() << "run_jobs on a worker with its own thread";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()), "field worker: run_jobs is for a worker made with JobThread::caller");
  }
}

/// Every message a worker sends, in order: progress (stage or "result").
struct SentMessages {
  std::mutex m;
  std::vector<std::pair<std::string, std::chrono::steady_clock::time_point>> sent;
  void add(std::string what) {
    std::lock_guard lock(m);
    sent.emplace_back(std::move(what), std::chrono::steady_clock::now());
  }
};

TEST(FieldWorker, ASilentJobStillShowsProgressPastAQuarterSecondAndNoneAfterItsResult) {
  using Clock = std::chrono::steady_clock;
  SentMessages log;
  FieldWorker worker([&](FieldWorker::Result) { log.add("result"); },
                     [&](json p) { log.add(p["stage"].get<std::string>() + "@" + std::to_string(p["generation"].get<std::uint64_t>())); });
  // One stage named at once (before the delay: not forwarded), then 0.6 s of silent work.
  const Clock::time_point submitted = Clock::now();
  worker.submit([&](const FieldWorker::Context& ctx) {
    ctx.progress("solving", 0.3);
    std::this_thread::sleep_for(std::chrono::milliseconds(600));
    return json{{"type", "result"}};
  });
  worker.wait_idle();
  std::lock_guard lock(log.m);
  ASSERT_GE(log.sent.size(), 2u) << "at least one heartbeat and the result";
  EXPECT_EQ(log.sent.back().first, "result") << "no progress after the result";
  // The job ran within [submitted, result]; heartbeats come a quarter second apart from its start.
  const double window_s = std::chrono::duration<double>(log.sent.back().second - submitted).count();
  const auto heartbeats = static_cast<double>(log.sent.size() - 1);
  EXPECT_LE(heartbeats, window_s / FieldWorker::kProgressDelay_s) << "at most one message per quarter second";
  for (std::size_t i = 0; i + 1 < log.sent.size(); ++i) {
    EXPECT_EQ(log.sent[i].first, "solving@1") << "the job's last stage, for its own generation";
    const double at_s = std::chrono::duration<double>(log.sent[i].second - submitted).count();
    EXPECT_GE(at_s, FieldWorker::kProgressDelay_s) << "nothing before a quarter second";
  }
}

TEST(FieldWorker, QuickJobsShowNoProgressAndAnUnnamedSlowJobIsComputing) {
  SentMessages log;
  FieldWorker worker([&](FieldWorker::Result) { log.add("result"); },
                     [&](json p) { log.add(p["stage"].get<std::string>()); });
  for (int i = 0; i < 5; ++i) {
    worker.submit([](const FieldWorker::Context& ctx) {
      ctx.progress("quick", 0.5);
      return json{{"type", "result"}};
    });
    worker.wait_idle();
  }
  {
    std::lock_guard lock(log.m);
    EXPECT_EQ(log.sent.size(), 5u) << "five results and no progress";
    log.sent.clear();
  }
  worker.submit([](const FieldWorker::Context&) {
    std::this_thread::sleep_for(std::chrono::milliseconds(400));
    return json{{"type", "result"}};
  });
  worker.wait_idle();
  std::lock_guard lock(log.m);
  ASSERT_GE(log.sent.size(), 2u);
  EXPECT_EQ(log.sent.front().first, "computing");
  EXPECT_EQ(log.sent.back().first, "result");
}

}  // namespace
}  // namespace cleave::studio
