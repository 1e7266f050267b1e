#include "cleaner.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "fake_host.hpp"

namespace agnocastd {
namespace {

using agnocast::ExitRecord;
using ::testing::ElementsAre;
using ::testing::IsEmpty;

ExitRecord queue_record(pid_t pid, std::string topic, std::uint32_t id) {
  return {ExitRecord::Kind::queue, pid, std::move(topic), id};
}
ExitRecord process_record(pid_t pid) { return {ExitRecord::Kind::process, pid, {}, 0}; }
ExitRecord lost_record(std::uint32_t count) { return {ExitRecord::Kind::lost, 0, {}, 0, count}; }

TEST(DeadProcessCollector, GroupsQueuesWithTheirProcess) {
  DeadProcessCollector collector;
  const auto dead = collector.add({queue_record(10, "/a/b", 1), queue_record(11, "/c", 0),
                                   queue_record(10, "/c", 2), process_record(10)});
  ASSERT_EQ(dead.size(), 1u);
  EXPECT_EQ(dead[0].pid, 10);
  EXPECT_THAT(dead[0].queues, ElementsAre("/a_b@1", "/c@2"));
  // Process 11's records were split across two reads.
  const auto later = collector.add({process_record(11), process_record(12)});
  ASSERT_EQ(later.size(), 2u);
  EXPECT_THAT(later[0].queues, ElementsAre("/c@0"));
  EXPECT_THAT(later[1].queues, IsEmpty());
}

TEST(CleanDeadProcess, RemovesItsQueuesThenCounts) {
  FakeHost host;
  host.queues = {"chatter@1", "chatter@2"};
  Counters counters;
  clean_dead_process({77, {"/chatter@1", "/gone@5"}}, host, counters);
  EXPECT_THAT(host.calls, ElementsAre("remove_queue /chatter@1", "remove_queue /gone@5"));
  EXPECT_EQ(host.queues, std::set<std::string>{"chatter@2"});
  EXPECT_EQ(counters.queues_removed, 1u);  // /gone@5 was not there
  EXPECT_EQ(counters.processes_cleaned, 1u);
}

TEST(CleanDeadProcess, RemovesItsDelayRecordOnlyWhenNoLiveProcessMadeIt) {
  FakeHost host;
  host.delay_records = {77, 78};
  Counters counters;
  clean_dead_process({77, {}}, host, counters);
  EXPECT_EQ(host.delay_records, std::set<pid_t>{78});
  // Pid 78 died, but a new process of that pid made the record now there.
  host.live_pids = {78};
  clean_dead_process({78, {}}, host, counters);
  EXPECT_EQ(host.delay_records, std::set<pid_t>{78});
  // Both as the kernel's exit records name them: a process on its way out is gone.
  EXPECT_THAT(host.delay_record_checks,
              ElementsAre(std::pair<pid_t, bool>{77, true}, std::pair<pid_t, bool>{78, true}));
}

TEST(HandleExitRecords, CleansCompletedProcessesWithoutSweeping) {
  FakeHost host;
  host.queues = {"a@1", "stale@9"};
  DeadProcessCollector collector;
  Counters counters;
  EXPECT_FALSE(handle_exit_records({queue_record(10, "/a", 1)}, collector, host, counters));
  EXPECT_TRUE(handle_exit_records({process_record(10)}, collector, host, counters));
  EXPECT_THAT(host.calls, ElementsAre("remove_queue /a@1"));
  EXPECT_EQ(host.queues, std::set<std::string>{"stale@9"});  // left for the periodic sweep
}

TEST(HandleExitRecords, LostRecordsSweepAtOnce) {
  FakeHost host;
  // Queues of processes whose records were discarded, and a live one.
  host.queues = {"a@1", "b@2", "c@4", "live@3"};
  host.live = {"/live@3"};
  DeadProcessCollector collector;
  Counters counters;
  EXPECT_FALSE(handle_exit_records({queue_record(10, "/a", 1)}, collector, host, counters));
  EXPECT_TRUE(handle_exit_records({lost_record(7), queue_record(11, "/c", 4), process_record(11)},
                                  collector, host, counters));
  EXPECT_EQ(host.queues, std::set<std::string>{"live@3"});
  EXPECT_EQ(counters.processes_cleaned, 1u);  // 11; 10's process record was lost
  EXPECT_EQ(counters.queues_removed, 3u);
  // The sweep came after the cleanup of process 11.
  ASSERT_FALSE(host.calls.empty());
  EXPECT_EQ(host.calls.front(), "remove_queue /c@4");
  EXPECT_EQ(collector.take_lost(), 0u);
  // A process record arriving after the loss no longer carries 10's queues.
  const auto later = collector.add({process_record(10)});
  ASSERT_EQ(later.size(), 1u);
  EXPECT_THAT(later[0].queues, IsEmpty());
}

TEST(DeadProcessCollector, CountsLostRecordsUntilTaken) {
  DeadProcessCollector collector;
  EXPECT_THAT(collector.add({lost_record(3)}), IsEmpty());
  EXPECT_THAT(collector.add({lost_record(4)}), IsEmpty());
  EXPECT_EQ(collector.take_lost(), 7u);
  EXPECT_EQ(collector.take_lost(), 0u);
}

}  // namespace
}  // namespace agnocastd
