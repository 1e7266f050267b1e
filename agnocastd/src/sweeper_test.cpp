#include "sweeper.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "fake_host.hpp"

namespace agnocastd {
namespace {

using ::testing::ElementsAre;
using ::testing::IsEmpty;

TEST(StaleQueues, OnlyAgnocastPatternFilesNoLiveSubscriberOwns) {
  EXPECT_THAT(stale_queues({"chatter@1", "chatter@2", "other", "x@", "a_b@07", "sensing_lidar@0"},
                           {"/chatter@2"}),
              ElementsAre("/chatter@1", "/sensing_lidar@0"));
}

TEST(StaleQueues, NothingListedNothingStale) {
  EXPECT_THAT(stale_queues({}, {"/chatter@1"}), IsEmpty());
}

TEST(Sweep, RemovesStaleQueuesAndKeepsLiveOnes) {
  FakeHost host;
  host.queues = {"foo@3", "chatter@1", "not-ours"};
  host.live = {"/chatter@1"};
  Counters counters;
  sweep(host, counters);
  EXPECT_EQ(host.queues, (std::set<std::string>{"chatter@1", "not-ours"}));
  EXPECT_EQ(counters.queues_removed, 1u);
}

TEST(Sweep, RemovesTheDelayRecordsOfProcessesGone) {
  FakeHost host;
  host.delay_records = {10, 11, 12};
  host.live_pids = {11};
  Counters counters;
  sweep(host, counters);
  EXPECT_EQ(host.delay_records, std::set<pid_t>{11});
  EXPECT_EQ(counters.queues_removed, 0u);  // records are not queues
  // No exit record names them: a process on its way out still lives.
  for (const auto& [pid, exit_reported] : host.delay_record_checks) EXPECT_FALSE(exit_reported);
  EXPECT_EQ(host.delay_record_checks.size(), 3u);
}

TEST(Sweep, ListsQueuesBeforeAskingTheKernel) {
  FakeHost host;
  host.queues = {"chatter@1"};
  // A subscriber that registers and creates its queue between the two reads.
  host.between_list_and_live = [&] {
    host.queues.insert("chatter@2");
    host.live.insert("/chatter@2");
  };
  host.live = {"/chatter@1"};
  Counters counters;
  sweep(host, counters);
  EXPECT_EQ(host.calls.at(0), "queue_files");
  EXPECT_EQ(host.calls.at(1), "live_queues");
  EXPECT_EQ(host.queues, (std::set<std::string>{"chatter@1", "chatter@2"}));
  EXPECT_EQ(counters.queues_removed, 0u);
}

TEST(Sweep, RemovesNoQueueWhenTheKernelCannotBeAsked) {
  FakeHost host;
  host.queues = {"chatter@1"};
  host.kernel_unreachable = true;
  Counters counters;
  sweep(host, counters);
  EXPECT_EQ(host.queues.size(), 1u);
  EXPECT_EQ(counters.queues_removed, 0u);
}

}  // namespace
}  // namespace agnocastd
