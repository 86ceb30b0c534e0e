#pragma once
// Recomputing after edits without a queue of stale work. The server submits one job per edit,
// numbered by a generation counter; the worker thread runs only the newest job it has not
// started, and a job that is superseded while it runs is told so (`superseded()` turns true)
// and its result is discarded. So after a burst of edits the worker does at most the job in
// flight plus the last one.
//
// Progress: a job that has run longer than kProgressDelay_s is reported at least every
// kProgressDelay_s (its latest stage and fraction, or "computing" before it named one), whether
// or not it calls `progress` itself; a second thread keeps that heartbeat. Every progress message
// of a job is published before its result.
//
//   FieldWorker worker([&](FieldWorker::Result r) { broadcast(r.message); });
//   worker.submit([&](const FieldWorker::Context& ctx) { ...; if (ctx.superseded()) return json{}; ... });
//
// The jobs run on a thread of the worker's own, or (JobThread::caller) on the thread that calls
// run_jobs() until stop(): `cleave studio` runs them on its main thread. glibc serves the main
// thread from its main heap, which keeps freed blocks for the next job (allocator_tuning.hpp);
// any other thread gets an arena that maps every block over 64 MB afresh and unmaps it when
// freed, so each new cut model's matrices and hierarchy (hundreds of MB at 45k cells) page-faulted
// in again: measured, a cut's first frame came 1.0 s after the cut and its second 1.2 s later.
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <functional>
#include <mutex>
#include <string>
#include <string_view>
#include <nlohmann/json.hpp>
#include <thread>

#include "cleave/core/progress.hpp"

namespace cleave::studio {

class FieldWorker {
 public:
  struct Context {
    std::uint64_t generation = 0;
    std::function<bool()> superseded;  ///< true once a newer job was submitted
    ProgressFn progress;               ///< stage and fraction; forwarded once the job is past kProgressDelay_s
  };
  using Job = std::function<nlohmann::json(const Context&)>;
  struct Result {
    std::uint64_t generation = 0;
    nlohmann::json message;
  };
  /// Called on the worker thread with each finished, current result (not for superseded jobs).
  using Publish = std::function<void(Result)>;
  /// Called on the worker or the heartbeat thread (never both at once) with
  /// {"type":"progress","generation":g,"stage":s,"fraction":f} for the current job once it has
  /// run longer than kProgressDelay_s, and again at least every kProgressDelay_s until it ends.
  using PublishProgress = std::function<void(nlohmann::json)>;

  /// Work that takes longer than this shows progress (issue 6: a quarter second), and the
  /// longest a running job goes without a progress message after that.
  static constexpr double kProgressDelay_s = 0.25;

  /// Where the jobs run (see above).
  enum class JobThread { own, caller };

  explicit FieldWorker(Publish publish, PublishProgress progress = {}, JobThread where = JobThread::own);
  /// Stops (the job in flight is superseded) and joins the worker's threads. With
  /// JobThread::caller, run_jobs() must have returned before.
  ~FieldWorker();
  FieldWorker(const FieldWorker&) = delete;
  FieldWorker& operator=(const FieldWorker&) = delete;

  /// Queues `job` as the newest generation (replacing a queued job that has not started) and
  /// returns its generation number (1, 2, ...).
  std::uint64_t submit(Job job);
  /// Blocks until every submitted job has finished or been dropped (for tests and shutdown).
  void wait_idle();
  /// JobThread::caller: runs the jobs on this thread until stop(). InputError for a worker with
  /// its own job thread.
  void run_jobs();
  /// Ends run_jobs() after the job in flight, which is superseded (any thread). No job starts after it.
  void stop();
  /// Jobs actually started so far (superseded queued jobs never start).
  std::uint64_t jobs_started() const { return started_.load(); }
  /// Queued jobs replaced by a newer one before they started. Every submitted job is started or
  /// skipped (once the worker is idle: submitted = started + skipped).
  std::uint64_t jobs_skipped() const { return skipped_.load(); }
  std::uint64_t jobs_submitted() const { return latest_.load(); }

 private:
  using Clock = std::chrono::steady_clock;
  void run();
  /// The heartbeat thread: forwards the running job's last stage when it has been quiet too long.
  void watch();
  /// Records the running job's stage and forwards it when the job is past the delay; needs report_mutex_.
  void report_locked(std::uint64_t generation, std::string_view stage, double fraction);
  void forward_locked(std::uint64_t generation);

  Publish publish_;
  PublishProgress progress_;
  std::mutex mutex_;
  std::condition_variable wake_;
  std::condition_variable idle_;
  Job pending_;
  std::uint64_t pending_generation_ = 0;
  std::atomic<std::uint64_t> latest_{0};
  std::atomic<std::uint64_t> started_{0};
  std::atomic<std::uint64_t> skipped_{0};
  bool busy_ = false;
  bool stopping_ = false;

  // The job in flight as the heartbeat sees it (guarded by report_mutex_; progress and the
  // result's hand-over are serialised by it, so no progress follows a result).
  std::mutex report_mutex_;
  std::condition_variable report_wake_;
  bool running_ = false;
  bool watcher_stopping_ = false;
  std::uint64_t running_generation_ = 0;
  Clock::time_point running_start_;
  Clock::time_point last_forwarded_;  ///< the job's start until its first progress message
  std::string stage_;
  double fraction_ = 0.0;

  JobThread where_;
  std::thread thread_;  ///< JobThread::own only
  std::thread watcher_;
};

}  // namespace cleave::studio
