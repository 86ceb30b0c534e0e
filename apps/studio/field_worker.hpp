#pragma once
// Recomputing after edits without a queue of stale work. The server submits one job per edit,
// numbered by a generation counter; the worker thread runs only the newest job it has not
// started, and a job that is superseded while it runs is told so (`superseded()` turns true)
// and its result is discarded. So after a burst of edits the worker does at most the job in
// flight plus the last one.
//
//   FieldWorker worker([&](FieldWorker::Result r) { broadcast(r.message); });
//   worker.submit([&](const FieldWorker::Context& ctx) { ...; if (ctx.superseded()) return json{}; ... });
#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <functional>
#include <mutex>
#include <nlohmann/json.hpp>
#include <thread>

#include "cleave/core/progress.hpp"

namespace cleave::studio {

class FieldWorker {
 public:
  struct Context {
    std::uint64_t generation = 0;
    std::function<bool()> superseded;  ///< true once a newer job was submitted
    ProgressFn progress;               ///< stage and fraction; forwarded after kProgressDelay_s
  };
  using Job = std::function<nlohmann::json(const Context&)>;
  struct Result {
    std::uint64_t generation = 0;
    nlohmann::json message;
  };
  /// Called on the worker thread with each finished, current result (not for superseded jobs).
  using Publish = std::function<void(Result)>;
  /// Called on the worker thread with {"type":"progress","generation":g,"stage":s,"fraction":f}
  /// for jobs that have run longer than kProgressDelay_s.
  using PublishProgress = std::function<void(nlohmann::json)>;

  /// Work that takes longer than this shows progress (issue 6: a quarter second).
  static constexpr double kProgressDelay_s = 0.25;

  explicit FieldWorker(Publish publish, PublishProgress progress = {});
  ~FieldWorker();
  FieldWorker(const FieldWorker&) = delete;
  FieldWorker& operator=(const FieldWorker&) = delete;

  /// Queues `job` as the newest generation (replacing a queued job that has not started) and
  /// returns its generation number (1, 2, ...).
  std::uint64_t submit(Job job);
  /// Blocks until every submitted job has finished or been dropped (for tests and shutdown).
  void wait_idle();
  /// Jobs actually started so far (superseded queued jobs never start).
  std::uint64_t jobs_started() const { return started_.load(); }

 private:
  void run();

  Publish publish_;
  PublishProgress progress_;
  std::mutex mutex_;
  std::condition_variable wake_;
  std::condition_variable idle_;
  Job pending_;
  std::uint64_t pending_generation_ = 0;
  std::atomic<std::uint64_t> latest_{0};
  std::atomic<std::uint64_t> started_{0};
  bool busy_ = false;
  bool stopping_ = false;
  std::thread thread_;
};

}  // namespace cleave::studio
