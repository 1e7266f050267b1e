#include "delay/delay_file.hpp"

#include <gtest/gtest.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <fstream>
#include <memory>
#include <string>
#include <vector>

#include "agnocast/inspect.hpp"

namespace agnocast::detail {
namespace {

std::int64_t now_ns() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(
             std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

// A pid no process has: a child's, once it is reaped.
pid_t dead_pid() {
  const pid_t child = ::fork();
  if (child == 0) ::_exit(0);
  int status = 0;
  ::waitpid(child, &status, 0);
  return child;
}

TEST(DelayFile, ARecorderWritesWhatAReaderOfItsProcessFinds) {
  DelayRecorder recorder("/delay/written", 7);
  ASSERT_TRUE(recorder.recording());
  const std::int64_t before = now_ns();
  recorder.record(before - 5'000'000);  // published 5 ms ago
  recorder.record(before);
  const std::int64_t after = now_ns();
  const auto delays = recorded_delays(::getpid(), "/delay/written", 7);
  ASSERT_TRUE(delays);
  EXPECT_EQ(delays->count, 2u);
  ASSERT_EQ(delays->newest_ns.size(), 2u);
  EXPECT_GE(delays->newest_ns[0], 5'000'000);
  EXPECT_LE(delays->newest_ns[0], after - before + 5'000'000);
  EXPECT_GE(delays->newest_ns[1], 0);
  EXPECT_LE(delays->newest_ns[1], after - before);
  // Another subscriber id, another topic: not found.
  EXPECT_FALSE(recorded_delays(::getpid(), "/delay/written", 8));
  EXPECT_FALSE(recorded_delays(::getpid(), "/delay/other", 7));
  // The file: everyone may read it, only its owner write it.
  struct stat status {};
  ASSERT_EQ(::stat(delay_file_path(::getpid()).c_str(), &status), 0);
  EXPECT_EQ(status.st_mode & 0777, 0644u);
}

TEST(DelayFile, TheRingKeepsTheNewestAndCountsThemAll) {
  DelayRecorder recorder("/delay/ring", 1);
  const std::int64_t base = now_ns() + 3'600'000'000'000;  // "published" an hour ahead
  for (int i = 0; i < 1500; ++i) recorder.record(base - i);
  const auto delays = recorded_delays(::getpid(), "/delay/ring", 1);
  ASSERT_TRUE(delays);
  EXPECT_EQ(delays->count, 1500u);
  ASSERT_EQ(delays->newest_ns.size(), delay_ring_size);
  // A publish time ahead of the clock is a delay of 0, not a negative one.
  for (const std::int64_t delay : delays->newest_ns) EXPECT_EQ(delay, 0);
}

TEST(DelayFile, ANoPublishTimeIsNotRecordedAndAGoneRecorderFreesItsSlot) {
  {
    DelayRecorder recorder("/delay/gone", 3);
    recorder.record(0);  // a header outside the pool: no publish time
    const auto delays = recorded_delays(::getpid(), "/delay/gone", 3);
    ASSERT_TRUE(delays);
    EXPECT_EQ(delays->count, 0u);
  }
  EXPECT_FALSE(recorded_delays(::getpid(), "/delay/gone", 3));
  // Its slot is free for the next, which counts from zero.
  DelayRecorder next("/delay/gone", 3);
  EXPECT_EQ(recorded_delays(::getpid(), "/delay/gone", 3)->count, 0u);
}

TEST(DelayFile, TheFileLastsAsLongAsItsRecorders) {
  const std::string path = delay_file_path(::getpid());
  {
    DelayRecorder first("/delay/lasting", 1);
    {
      DelayRecorder second("/delay/lasting", 2);
      EXPECT_EQ(::access(path.c_str(), F_OK), 0);
    }
    EXPECT_EQ(::access(path.c_str(), F_OK), 0);
    EXPECT_TRUE(recorded_delays(::getpid(), "/delay/lasting", 1));
  }
  EXPECT_NE(::access(path.c_str(), F_OK), 0);
  // The next recorder makes it again.
  DelayRecorder again("/delay/lasting", 3);
  EXPECT_TRUE(recorded_delays(::getpid(), "/delay/lasting", 3));
}

TEST(DelayFile, AForkChildsCopyOfARecorderFreesNothingOfItsParents) {
  auto recorder = std::make_unique<DelayRecorder>("/delay/forked", 1);
  const pid_t child = ::fork();
  if (child == 0) {
    recorder.reset();  // the parent's slot: left alone
    bool own_file = false;
    {
      DelayRecorder own("/delay/child", 2);
      own_file = own.recording() && ::access(delay_file_path(::getpid()).c_str(), F_OK) == 0;
    }
    const bool removed = ::access(delay_file_path(::getpid()).c_str(), F_OK) != 0;
    ::_exit(own_file && removed ? 0 : 1);
  }
  int status = 0;
  ASSERT_EQ(::waitpid(child, &status, 0), child);
  EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0);
  EXPECT_TRUE(recorded_delays(::getpid(), "/delay/forked", 1));
}

TEST(DelayFile, ANameAnotherUserTookIsLeftAloneAndNothingIsRecorded) {
  if (::geteuid() != 0) GTEST_SKIP() << "making a file of another user needs root";
  const std::string path = delay_file_path(::getpid());
  std::ofstream(path) << "planted";
  ASSERT_EQ(::chown(path.c_str(), 65534, 65534), 0);
  {
    DelayRecorder recorder("/delay/planted", 1);
    EXPECT_FALSE(recorder.recording());
    recorder.record(now_ns());
  }
  std::ifstream planted(path);
  EXPECT_EQ(
      std::string((std::istreambuf_iterator<char>(planted)), std::istreambuf_iterator<char>()),
      "planted");
  std::remove(path.c_str());
  // Its own user's leftover (a dead process of this pid) is replaced.
  std::ofstream(path) << "left";
  DelayRecorder recorder("/delay/planted", 1);
  EXPECT_TRUE(recorder.recording());
  EXPECT_TRUE(recorded_delays(::getpid(), "/delay/planted", 1));
}

TEST(DelayFile, EverySlotTakenLeavesTheNextRecorderWithout) {
  std::vector<std::unique_ptr<DelayRecorder>> recorders;
  for (std::uint32_t i = 0; i < delay_slots; ++i) {
    recorders.push_back(std::make_unique<DelayRecorder>("/delay/full", i));
  }
  DelayRecorder extra("/delay/full", delay_slots);
  EXPECT_FALSE(extra.recording());
  extra.record(now_ns());  // harmless
  recorders.pop_back();
  EXPECT_TRUE(DelayRecorder("/delay/full", delay_slots).recording());
}

TEST(DelayFile, AReaderBelievesNoFileThatIsNotOneOfItsProcess) {
  // Another process's name: a file the reader does not trust.
  const pid_t gone = dead_pid();
  const std::string path = delay_file_path(gone);
  auto write = [&](const std::string& bytes) {
    std::ofstream(path, std::ios::binary | std::ios::trunc) << bytes;
  };
  write("not a delay file");
  EXPECT_FALSE(recorded_delays(gone, "/delay/x", 0));
  // A copy of a real one, of the right size, for a process that is gone.
  DelayRecorder recorder("/delay/x", 0);
  recorder.record(now_ns());
  std::ifstream own(delay_file_path(::getpid()), std::ios::binary);
  write(std::string((std::istreambuf_iterator<char>(own)), std::istreambuf_iterator<char>()));
  EXPECT_FALSE(recorded_delays(gone, "/delay/x", 0));  // its pid and start time are not gone's
  // A symbolic link is not followed.
  std::remove(path.c_str());
  ASSERT_EQ(::symlink(delay_file_path(::getpid()).c_str(), path.c_str()), 0);
  EXPECT_FALSE(recorded_delays(gone, "/delay/x", 0));
  std::remove(path.c_str());
}

TEST(DelayFile, OnlyTheRecordsOfProcessesGoneAreStale) {
  DelayRecorder recorder("/delay/stale", 0);
  const pid_t gone = dead_pid();
  std::ofstream(delay_file_path(gone)) << "left behind";
  const std::vector<pid_t> pids = delay_record_pids();
  EXPECT_NE(std::find(pids.begin(), pids.end(), ::getpid()), pids.end());
  EXPECT_NE(std::find(pids.begin(), pids.end(), gone), pids.end());
  EXPECT_FALSE(remove_stale_delay_record(::getpid()));
  // An exit record of this pid while a process of it is not exiting: a new
  // process's record, kept.
  EXPECT_FALSE(remove_stale_delay_record(::getpid(), true));
  EXPECT_TRUE(remove_stale_delay_record(gone));
  EXPECT_FALSE(remove_stale_delay_record(gone));  // gone already
  EXPECT_TRUE(recorded_delays(::getpid(), "/delay/stale", 0));
}

TEST(DelayFile, TheStartTimeOfAProcessIsItsOwnAndNoneOnceItIsGone) {
  const auto own = process_start_time(::getpid());
  ASSERT_TRUE(own);
  EXPECT_EQ(process_start_time(::getpid()), own);
  EXPECT_FALSE(process_start_time(dead_pid()));
  // A zombie, not reaped yet, lives no more: its record is stale already.
  const pid_t zombie = ::fork();
  if (zombie == 0) ::_exit(0);
  siginfo_t info{};
  ASSERT_EQ(::waitid(P_PID, static_cast<id_t>(zombie), &info, WEXITED | WNOWAIT), 0);
  EXPECT_FALSE(process_start_time(zombie));
  std::ofstream(delay_file_path(zombie)) << "left behind";
  EXPECT_TRUE(remove_stale_delay_record(zombie));
  int status = 0;
  ::waitpid(zombie, &status, 0);
}

}  // namespace
}  // namespace agnocast::detail
