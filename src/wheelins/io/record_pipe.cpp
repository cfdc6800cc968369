// The record hand-over between threads of record_pipe.hpp.
#include "wheelins/io/record_pipe.hpp"

namespace wheelins {

RecordPipe::RecordPipe(Consumer consumer, std::size_t batch, std::size_t batches)
    : consumer_(std::move(consumer)),
      batch_size_(batch < 1 ? 1 : batch),
      pool_(batches < 2 ? 2 : batches),
      full_(pool_.size()),
      free_(pool_.size()) {
  for (auto& b : pool_) b.reserve(batch_size_);
  // Batch 0 is the producer's; the rest are free.
  current_ = 0;
  for (std::size_t i = 1; i < pool_.size(); ++i) free_[free_count_++] = i;
  thread_ = std::thread([this] { run(); });
}

RecordPipe::~RecordPipe() { stop(); }

void RecordPipe::push(int stream, const TrajectoryRecord& record) {
  Batch& b = pool_[current_];
  b.emplace_back(stream, record);
  if (b.size() >= batch_size_) hand_over();
}

void RecordPipe::hand_over() {
  std::unique_lock<std::mutex> lock(mutex_);
  if (error_) {
    // The consumer has failed: stop producing and report it (the records are lost).
    std::exception_ptr e = error_;
    pool_[current_].clear();
    lock.unlock();
    std::rethrow_exception(e);
  }
  full_[(full_head_ + full_count_) % full_.size()] = current_;
  ++full_count_;
  to_writer_.notify_one();
  to_producer_.wait(lock, [this] { return free_count_ > 0; });
  current_ = free_[free_head_];
  free_head_ = (free_head_ + 1) % free_.size();
  --free_count_;
}

void RecordPipe::run() {
  for (;;) {
    std::size_t index;
    {
      std::unique_lock<std::mutex> lock(mutex_);
      to_writer_.wait(lock, [this] { return full_count_ > 0 || done_; });
      if (full_count_ == 0) return;  // done and drained
      index = full_[full_head_];
      full_head_ = (full_head_ + 1) % full_.size();
      --full_count_;
    }
    Batch& b = pool_[index];
    bool failed;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      failed = static_cast<bool>(error_);
    }
    if (!failed) {
      try {
        for (const auto& [stream, rec] : b) consumer_(stream, rec);
      } catch (...) {
        std::lock_guard<std::mutex> lock(mutex_);
        error_ = std::current_exception();
      }
    }
    b.clear();
    {
      std::lock_guard<std::mutex> lock(mutex_);
      free_[(free_head_ + free_count_) % free_.size()] = index;
      ++free_count_;
    }
    to_producer_.notify_one();
  }
}

void RecordPipe::stop() {
  if (stopped_) return;
  stopped_ = true;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    done_ = true;
  }
  to_writer_.notify_one();
  if (thread_.joinable()) thread_.join();
}

void RecordPipe::finish() {
  if (!pool_[current_].empty()) hand_over();
  stop();
  if (error_) std::rethrow_exception(error_);
}

}  // namespace wheelins
