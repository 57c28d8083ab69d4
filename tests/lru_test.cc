// base/lru.h: eviction order, budgets, touch, erase.
#include "base/lru.h"

#include <string>
#include <utility>
#include <vector>

#include "gtest/gtest.h"

namespace sfc {
namespace {

using StringLru = Lru<std::string, int>;

// Pops everything, least recently used first, and returns the keys.
std::vector<std::string> DrainOrder(StringLru& lru) {
  std::vector<std::string> order;
  while (!lru.empty()) order.push_back(lru.PopLeastRecent().key);
  return order;
}

TEST(LruTest, EvictsLeastRecentlyInsertedFirst) {
  StringLru lru;
  EXPECT_TRUE(lru.Insert("a", 1, 1));
  EXPECT_TRUE(lru.Insert("b", 2, 1));
  EXPECT_TRUE(lru.Insert("c", 3, 1));
  EXPECT_EQ(DrainOrder(lru), (std::vector<std::string>{"a", "b", "c"}));
  EXPECT_TRUE(lru.empty());
  EXPECT_EQ(lru.total_cost(), 0u);
}

TEST(LruTest, TouchMakesMostRecentFindDoesNot) {
  StringLru lru;
  lru.Insert("a", 1, 1);
  lru.Insert("b", 2, 1);
  lru.Insert("c", 3, 1);
  ASSERT_NE(lru.Touch("a"), nullptr);
  EXPECT_EQ(*lru.Touch("a"), 1);
  ASSERT_NE(lru.Find("b"), nullptr);  // no change of order
  EXPECT_EQ(lru.Touch("missing"), nullptr);
  EXPECT_EQ(lru.Find("missing"), nullptr);
  EXPECT_EQ(DrainOrder(lru), (std::vector<std::string>{"b", "c", "a"}));
}

TEST(LruTest, InsertOfAKeptKeyChangesNothing) {
  StringLru lru;
  lru.Insert("a", 1, 10);
  lru.Insert("b", 2, 20);
  EXPECT_FALSE(lru.Insert("a", 99, 1000));
  EXPECT_EQ(*lru.Find("a"), 1);
  EXPECT_EQ(lru.total_cost(), 30u);
  EXPECT_EQ(DrainOrder(lru), (std::vector<std::string>{"a", "b"}));
}

TEST(LruTest, EvictionHonoursTheBudgetAndCountsCosts) {
  StringLru lru;
  const uint64_t budget = 100;
  std::vector<std::pair<std::string, uint64_t>> evicted;
  for (int i = 0; i < 10; ++i) {
    lru.Insert("k" + std::to_string(i), i, 30);
    while (!lru.empty() && lru.total_cost() > budget) {
      StringLru::Entry entry = lru.PopLeastRecent();
      EXPECT_EQ(entry.value, std::stoi(entry.key.substr(1)));
      evicted.emplace_back(entry.key, entry.cost);
    }
    EXPECT_LE(lru.total_cost(), budget);
    EXPECT_EQ(lru.total_cost(), 30 * lru.size());
  }
  EXPECT_EQ(lru.size(), 3u);
  ASSERT_EQ(evicted.size(), 7u);
  for (int i = 0; i < 7; ++i) {
    EXPECT_EQ(evicted[i].first, "k" + std::to_string(i));
    EXPECT_EQ(evicted[i].second, 30u);
  }
}

TEST(LruTest, AnEntryOverTheBudgetAloneIsKeptOnlyByTheOwnersChoice) {
  // As the model store does: evict while over budget but keep the newest.
  StringLru lru;
  const uint64_t budget = 10;
  lru.Insert("small", 1, 4);
  lru.Insert("huge", 2, 50);
  while (lru.total_cost() > budget && lru.size() > 1) lru.PopLeastRecent();
  EXPECT_EQ(lru.size(), 1u);
  EXPECT_NE(lru.Find("huge"), nullptr);
  EXPECT_EQ(lru.total_cost(), 50u);
}

TEST(LruTest, EraseAndEraseIfRemoveEntriesAndTheirCost) {
  StringLru lru;
  lru.Insert("x1", 1, 5);
  lru.Insert("y", 2, 7);
  lru.Insert("x2", 3, 11);
  EXPECT_TRUE(lru.Erase("y"));
  EXPECT_FALSE(lru.Erase("y"));
  EXPECT_EQ(lru.Find("y"), nullptr);
  EXPECT_EQ(lru.total_cost(), 16u);
  lru.Insert("y", 4, 7);
  lru.EraseIf([](const std::string& key, int) { return key[0] == 'x'; });
  EXPECT_EQ(lru.size(), 1u);
  EXPECT_EQ(lru.total_cost(), 7u);
  EXPECT_EQ(*lru.Find("y"), 4);
}

}  // namespace
}  // namespace sfc
