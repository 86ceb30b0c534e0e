#include "studio/field_worker.hpp"

#include <chrono>
#include <string>

#include "cleave/core/error.hpp"

namespace cleave::studio {

namespace {

constexpr const char* kUnnamedStage = "computing";  ///< the heartbeat's stage before a job names one

}  // namespace

FieldWorker::FieldWorker(Publish publish, PublishProgress progress, JobThread where)
    : publish_(std::move(publish)), progress_(std::move(progress)), where_(where), watcher_([this] { watch(); }) {
  if (where_ == JobThread::own) thread_ = std::thread([this] { run(); });
}

void FieldWorker::stop() {
  {
    std::lock_guard lock(mutex_);
    stopping_ = true;
    pending_ = nullptr;
  }
  latest_.fetch_add(1);  // whatever runs now is superseded
  wake_.notify_all();
  idle_.notify_all();
}

void FieldWorker::run_jobs() {
  if (where_ != JobThread::caller) throw InputError("field worker: run_jobs is for a worker made with JobThread::caller");
  run();
}

FieldWorker::~FieldWorker() {
  stop();
  if (thread_.joinable()) thread_.join();
  {
    std::lock_guard lock(report_mutex_);
    watcher_stopping_ = true;
  }
  report_wake_.notify_all();
  watcher_.join();
}

std::uint64_t FieldWorker::submit(Job job) {
  std::uint64_t generation = 0;
  {
    std::lock_guard lock(mutex_);
    generation = latest_.fetch_add(1) + 1;
    if (pending_) skipped_.fetch_add(1);  // the queued job never starts
    pending_ = std::move(job);
    pending_generation_ = generation;
  }
  wake_.notify_all();
  return generation;
}

void FieldWorker::wait_idle() {
  std::unique_lock lock(mutex_);
  idle_.wait(lock, [this] { return (!pending_ && !busy_) || stopping_; });
}

void FieldWorker::forward_locked(std::uint64_t generation) {
  last_forwarded_ = Clock::now();
  if (progress_ && latest_.load() == generation)
    progress_({{"type", "progress"}, {"generation", generation}, {"stage", stage_}, {"fraction", fraction_}});
}

void FieldWorker::report_locked(std::uint64_t generation, std::string_view stage, double fraction) {
  if (!running_ || running_generation_ != generation) return;
  stage_ = std::string(stage);
  fraction_ = fraction;
  const double elapsed_s = std::chrono::duration<double>(Clock::now() - running_start_).count();
  if (elapsed_s > kProgressDelay_s) forward_locked(generation);
}

void FieldWorker::watch() {
  const auto delay = std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(kProgressDelay_s));
  std::unique_lock lock(report_mutex_);
  for (;;) {
    if (watcher_stopping_) return;
    if (!running_) {
      report_wake_.wait(lock);
      continue;
    }
    const Clock::time_point due = last_forwarded_ + delay;
    if (Clock::now() < due) {
      report_wake_.wait_until(lock, due);  // woken early by the job's end (or a spurious wake): look again
      continue;
    }
    forward_locked(running_generation_);
  }
}

void FieldWorker::run() {
  for (;;) {
    Job job;
    std::uint64_t generation = 0;
    {
      std::unique_lock lock(mutex_);
      wake_.wait(lock, [this] { return stopping_ || pending_; });
      if (stopping_) return;
      job = std::move(pending_);
      pending_ = nullptr;
      generation = pending_generation_;
      busy_ = true;
    }
    started_.fetch_add(1);
    {
      std::lock_guard lock(report_mutex_);
      running_ = true;
      running_generation_ = generation;
      running_start_ = last_forwarded_ = Clock::now();
      stage_ = kUnnamedStage;
      fraction_ = 0.0;
    }
    report_wake_.notify_all();
    Context ctx;
    ctx.generation = generation;
    ctx.superseded = [this, generation] { return latest_.load() != generation; };
    ctx.progress = [this, generation](std::string_view stage, double fraction) {
      std::lock_guard lock(report_mutex_);
      report_locked(generation, stage, fraction);
    };
    nlohmann::json message;
    try {
      message = job(ctx);
    } catch (const InputError& e) {
      message = {{"type", "error"}, {"message", e.what()}};
    } catch (const ComputeError& e) {
      message = {{"type", "error"}, {"message", std::string("computation failed: ") + e.what()}};
    } catch (const std::bad_alloc&) {
      message = {{"type", "error"}, {"message", "computation failed: out of memory"}};
    }
    {
      std::lock_guard lock(report_mutex_);  // a heartbeat in flight is sent before the result
      running_ = false;
    }
    report_wake_.notify_all();
    if (!ctx.superseded() && !message.is_null()) publish_({generation, std::move(message)});
    {
      std::lock_guard lock(mutex_);
      busy_ = false;
    }
    idle_.notify_all();
  }
}

}  // namespace cleave::studio
