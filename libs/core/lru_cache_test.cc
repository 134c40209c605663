#include "core/lru_cache.h"

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

namespace jvl {
namespace {

TEST(LruCache, MakesEachValueOnceAndDropsTheLeastRecentlyUsed) {
  LruCache<int, std::string> cache(2);
  int made = 0;
  auto make = [&](int k) {
    return [&made, k] {
      ++made;
      return "v" + std::to_string(k);
    };
  };
  EXPECT_EQ(*cache.Get(1, make(1)), "v1");
  EXPECT_EQ(*cache.Get(2, make(2)), "v2");
  EXPECT_EQ(*cache.Get(1, make(1)), "v1");  // Kept: 1 is now the most recently used.
  EXPECT_EQ(made, 2);
  const auto held = cache.Get(2, make(2));
  EXPECT_EQ(made, 2);
  cache.Get(3, make(3));  // Drops 1, the least recently used.
  EXPECT_EQ(made, 3);
  EXPECT_EQ(cache.size(), 2u);
  EXPECT_EQ(cache.Find(1), nullptr);
  ASSERT_NE(cache.Find(2), nullptr);
  EXPECT_EQ(*cache.Find(3), "v3");
  cache.Get(1, make(1));  // Made again; drops 2, whose value lives on in `held`.
  EXPECT_EQ(made, 4);
  EXPECT_EQ(cache.Find(2), nullptr);
  EXPECT_EQ(*held, "v2");
}

TEST(LruCache, FindIsNotAUse) {
  LruCache<int, int> cache(2);
  cache.Get(1, [] { return 10; });
  cache.Get(2, [] { return 20; });
  EXPECT_EQ(*cache.Find(1), 10);  // Does not make 1 the most recently used ...
  cache.Get(3, [] { return 30; });
  EXPECT_EQ(cache.Find(1), nullptr);  // ... so 1 goes.
  EXPECT_EQ(cache.Find(4), nullptr);  // Nothing is made.
  EXPECT_EQ(cache.size(), 2u);
}

TEST(LruCache, AFailedMakeIsRetried) {
  LruCache<int, int> cache(4);
  EXPECT_THROW(cache.Get(1, []() -> int { throw std::runtime_error("no"); }), std::runtime_error);
  EXPECT_EQ(cache.Find(1), nullptr);
  EXPECT_EQ(*cache.Get(1, [] { return 7; }), 7);
}

TEST(LruCache, ThreadsAskingForOneKeyShareOneMake) {
  LruCache<int, int> cache(8);
  std::atomic<int> made{0};
  std::vector<std::thread> threads;
  std::vector<int> seen(16, 0);
  for (int t = 0; t < 16; ++t) {
    threads.emplace_back([&, t] {
      seen[static_cast<size_t>(t)] = *cache.Get(t % 4, [&, t] {
        ++made;
        std::this_thread::sleep_for(std::chrono::milliseconds(5));
        return 100 + t % 4;
      });
    });
  }
  for (std::thread& thread : threads) thread.join();
  EXPECT_EQ(made.load(), 4);
  for (int t = 0; t < 16; ++t) EXPECT_EQ(seen[static_cast<size_t>(t)], 100 + t % 4);
}

}  // namespace
}  // namespace jvl
