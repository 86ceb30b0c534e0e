#include "studio/field_worker.hpp"

#include <chrono>
#include <string>

#include "cleave/core/error.hpp"

namespace cleave::studio {

FieldWorker::FieldWorker(Publish publish, PublishProgress progress)
    : publish_(std::move(publish)), progress_(std::move(progress)), thread_([this] { run(); }) {}

FieldWorker::~FieldWorker() {
  {
    std::lock_guard lock(mutex_);
    stopping_ = true;
    pending_ = nullptr;
  }
  latest_.fetch_add(1);  // whatever runs now is superseded
  wake_.notify_all();
  thread_.join();
}

std::uint64_t FieldWorker::submit(Job job) {
  std::uint64_t generation = 0;
  {
    std::lock_guard lock(mutex_);
    generation = latest_.fetch_add(1) + 1;
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

void FieldWorker::run() {
  using Clock = std::chrono::steady_clock;
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
    const auto start = Clock::now();
    Context ctx;
    ctx.generation = generation;
    ctx.superseded = [this, generation] { return latest_.load() != generation; };
    ctx.progress = [this, generation, start](std::string_view stage, double fraction) {
      const double elapsed_s = std::chrono::duration<double>(Clock::now() - start).count();
      if (progress_ && elapsed_s > kProgressDelay_s && latest_.load() == generation)
        progress_({{"type", "progress"}, {"generation", generation}, {"stage", std::string(stage)}, {"fraction", fraction}});
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
    if (!ctx.superseded() && !message.is_null()) publish_({generation, std::move(message)});
    {
      std::lock_guard lock(mutex_);
      busy_ = false;
    }
    idle_.notify_all();
  }
}

}  // namespace cleave::studio
