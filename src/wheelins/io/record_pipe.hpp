// Hands trajectory records from the navigation thread to a writer thread, so that
// formatting text and writing files run on a second core while the filter goes on.
// Records travel in batches through a fixed pool (no allocation per record); the
// consumer sees them in the order they were pushed. An exception thrown by the
// consumer (e.g. a full disk) is passed back to the producer at its next push() or
// at finish(): nothing is lost silently.
#pragma once

#include <condition_variable>
#include <cstddef>
#include <exception>
#include <functional>
#include <mutex>
#include <thread>
#include <utility>
#include <vector>

#include "wheelins/io/trajectory.hpp"

namespace wheelins {

class RecordPipe {
 public:
  using Consumer = std::function<void(int stream, const TrajectoryRecord&)>;

  /// Starts the writer thread. `batch` records per hand-over, `batches` in the pool
  /// (the producer waits when all are full).
  explicit RecordPipe(Consumer consumer, std::size_t batch = 256, std::size_t batches = 8);
  ~RecordPipe();  ///< joins the thread; a pending consumer error is dropped (call finish())
  RecordPipe(const RecordPipe&) = delete;
  RecordPipe& operator=(const RecordPipe&) = delete;

  /// Queues a record (copied). Rethrows a consumer error.
  void push(int stream, const TrajectoryRecord& record);
  /// Hands over the last partial batch, waits until the consumer has seen every record,
  /// stops the thread, and rethrows a consumer error.
  void finish();

 private:
  using Batch = std::vector<std::pair<int, TrajectoryRecord>>;
  void hand_over();  ///< the current batch to the writer; takes a free one
  void run();
  void stop();

  Consumer consumer_;
  std::size_t batch_size_;
  std::vector<Batch> pool_;
  std::vector<std::size_t> full_, free_;  ///< FIFO rings of pool indices
  std::size_t full_head_ = 0, full_count_ = 0, free_head_ = 0, free_count_ = 0;
  std::size_t current_;                   ///< batch being filled by the producer
  std::mutex mutex_;
  std::condition_variable to_writer_, to_producer_;
  bool done_ = false;
  bool stopped_ = false;
  std::exception_ptr error_;
  std::thread thread_;
};

}  // namespace wheelins
