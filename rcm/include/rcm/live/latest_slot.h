// LatestSlot<T>: a queue of one between a producer that must never wait
// (a middleware's callback delivering stereo pairs) and a consumer that may
// be slower (LivePipeline::Process). Put replaces an item not yet taken
// and counts it as dropped: under overload the latest pair wins, whole
// pairs are dropped, and memory never grows. Take waits for an item (or
// Close, or the timeout).
//
// Thread-safe: any number of producers and consumers.
#ifndef RCM_LIVE_LATEST_SLOT_H_
#define RCM_LIVE_LATEST_SLOT_H_

#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <mutex>
#include <optional>
#include <utility>

namespace rcm {

template <typename T>
class LatestSlot {
 public:
  // Stores `item`; true when it replaced one not yet taken (a drop).
  bool Put(T item) {
    bool dropped = false;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      dropped = item_.has_value();
      if (dropped) ++num_dropped_;
      ++num_put_;
      item_ = std::move(item);
    }
    ready_.notify_one();
    return dropped;
  }

  // The item, waiting up to `timeout` for one; nullopt on timeout or once
  // closed.
  template <typename Rep, typename Period>
  std::optional<T> Take(std::chrono::duration<Rep, Period> timeout) {
    std::unique_lock<std::mutex> lock(mutex_);
    ready_.wait_for(lock, timeout,
                    [this] { return closed_ || item_.has_value(); });
    if (closed_ || !item_) return std::nullopt;
    std::optional<T> item = std::move(item_);
    item_.reset();
    return item;
  }

  // Wakes every Take, which then returns nullopt; Put still stores.
  void Close() {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      closed_ = true;
    }
    ready_.notify_all();
  }

  int64_t num_dropped() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return num_dropped_;
  }
  int64_t num_put() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return num_put_;
  }

 private:
  mutable std::mutex mutex_;
  std::condition_variable ready_;
  std::optional<T> item_;
  bool closed_ = false;
  int64_t num_dropped_ = 0;
  int64_t num_put_ = 0;
};

}  // namespace rcm

#endif  // RCM_LIVE_LATEST_SLOT_H_
