// A thread-safe cache of the values of the most recently used keys, each value made once.
#pragma once

#include <cstddef>
#include <list>
#include <memory>
#include <mutex>
#include <unordered_map>
#include <utility>

namespace jvl {

// Keeps the values of the `capacity` most recently used keys. A missing value is made by the
// caller's function outside the cache's lock, once while its key is kept: other threads asking
// for the same key wait for it, threads asking for other keys do not (a key dropped while its
// value is being made, and asked for again, is made again). A value dropped from the cache lives
// on while a caller holds it.
template <typename Key, typename Value>
class LruCache {
 public:
  explicit LruCache(size_t capacity) : capacity_(capacity < 1 ? 1 : capacity) {}

  // The value of `key`, made by make() (returning a Value) if it is not kept; a use.
  template <typename Make>
  std::shared_ptr<const Value> Get(const Key& key, Make&& make) {
    std::shared_ptr<Slot> slot;
    {
      const std::lock_guard<std::mutex> lock(mutex_);
      recent_.push_front(key);  // First: nothing below is left half done if it throws.
      auto it = slots_.find(key);
      if (it != slots_.end()) {
        recent_.erase(it->second.second);
        it->second.second = recent_.begin();
      } else {
        try {
          it = slots_.emplace(key, std::make_pair(std::make_shared<Slot>(), recent_.begin())).first;
        } catch (...) {
          recent_.pop_front();
          throw;
        }
      }
      slot = it->second.first;
      while (recent_.size() > capacity_) {  // The least recently used one goes.
        slots_.erase(recent_.back());
        recent_.pop_back();
      }
    }
    const std::lock_guard<std::mutex> lock(slot->mutex);
    if (!slot->value) slot->value = std::make_shared<const Value>(make());
    return slot->value;
  }

  // The value of `key` if it is kept and made, else null; not a use, nothing is made.
  std::shared_ptr<const Value> Find(const Key& key) {
    std::shared_ptr<Slot> slot;
    {
      const std::lock_guard<std::mutex> lock(mutex_);
      const auto it = slots_.find(key);
      if (it == slots_.end()) return nullptr;
      slot = it->second.first;
    }
    const std::lock_guard<std::mutex> lock(slot->mutex);
    return slot->value;
  }

  size_t capacity() const { return capacity_; }
  size_t size() {
    const std::lock_guard<std::mutex> lock(mutex_);
    return slots_.size();
  }

 private:
  struct Slot {
    std::mutex mutex;
    std::shared_ptr<const Value> value;
  };
  const size_t capacity_;
  std::mutex mutex_;
  std::list<Key> recent_;  // Most recently used first.
  std::unordered_map<Key, std::pair<std::shared_ptr<Slot>, typename std::list<Key>::iterator>>
      slots_;
};

}  // namespace jvl
