#include "core/worker_governor.h"

#include <gtest/gtest.h>

#include <time.h>

namespace handlabel {
namespace {

using std::chrono::milliseconds;

// A scripted machine: the clock moves when the test says, and the scheduler times add
// what the test says the workers got in each window.
struct ScriptedMachine {
  WorkerGovernor::Clock::time_point now{};
  SchedulerTimes times;
  bool readable = true;
  // One window of `ms` in which the running threads were on a core for `run` and
  // waited for one for `wait` (shares of the window's length).
  void Pass(int ms, double run, double wait) {
    now += milliseconds(ms);
    times.run_ns += run * ms * 1e6;
    times.wait_ns += wait * ms * 1e6;
  }
  WorkerGovernor Governor(int workers) {
    return WorkerGovernor(
        workers, {},
        [this]() -> std::optional<SchedulerTimes> {
          if (!readable) return std::nullopt;
          return times;
        },
        [this] { return now; });
  }
};

TEST(WorkerGovernor, KeepsEveryWorkerOnFreeCores) {
  ScriptedMachine m;
  WorkerGovernor g = m.Governor(2);
  for (int i = 0; i < 40; ++i) {
    m.Pass(500, 1.9, 0.05);  // two workers, each on its own core
    EXPECT_TRUE(g.MayRun(1));
  }
  EXPECT_EQ(g.parks(), 0);
}

TEST(WorkerGovernor, ParksWhenTheWorkersShareOneCoreAndProbesWithGrowingPauses) {
  ScriptedMachine m;
  WorkerGovernor g = m.Governor(2);
  EXPECT_TRUE(g.MayRun(1));
  m.Pass(500, 1.0, 1.0);  // two runnable workers, one core between them: wait 0.5
  EXPECT_FALSE(g.MayRun(1));
  EXPECT_TRUE(g.MayRun(0));  // the first worker always runs
  EXPECT_EQ(g.running(), 1);
  // Parked, the first worker waits for nothing; no probe before the first pause (4 s).
  for (int i = 0; i < 7; ++i) {
    m.Pass(500, 1.0, 0.0);
    EXPECT_FALSE(g.MayRun(1)) << "window " << i;
  }
  m.Pass(500, 1.0, 0.0);  // 4 s after parking: a probe window with every worker
  EXPECT_TRUE(g.MayRun(1));
  m.Pass(500, 1.0, 1.0);  // still one core's worth: parked again, now for 8 s
  EXPECT_FALSE(g.MayRun(1));
  EXPECT_EQ(g.parks(), 2);
  for (int i = 0; i < 15; ++i) {
    m.Pass(500, 1.0, 0.0);
    EXPECT_FALSE(g.MayRun(1)) << "window " << i;
  }
  m.Pass(500, 1.0, 0.0);
  EXPECT_TRUE(g.MayRun(1));  // the probe after 8 s
  m.Pass(500, 1.95, 0.05);   // the other process has ended: everybody keeps running
  EXPECT_TRUE(g.MayRun(1));
  m.Pass(500, 1.0, 1.0);  // busy again: parked with the first pause (4 s), not 16
  EXPECT_FALSE(g.MayRun(1));
  for (int i = 0; i < 7; ++i) {
    m.Pass(500, 1.0, 0.0);
    EXPECT_FALSE(g.MayRun(1));
  }
  m.Pass(500, 1.0, 0.0);
  EXPECT_TRUE(g.MayRun(1));
}

TEST(WorkerGovernor, MoreWorkersThanCoresKeepAsManyAsTheCores) {
  // Four workers on two free cores: each runnable worker waits half of the time.
  ScriptedMachine m;
  WorkerGovernor g = m.Governor(4);
  m.Pass(500, 2.0, 2.0);
  EXPECT_TRUE(g.MayRun(1));
  EXPECT_FALSE(g.MayRun(2));
  EXPECT_FALSE(g.MayRun(3));
  EXPECT_EQ(g.running(), 2);
  // Four workers sharing one core (another process on the other): one runs.
  WorkerGovernor busy = m.Governor(4);
  m.Pass(500, 1.0, 3.0);
  EXPECT_FALSE(busy.MayRun(1));
  EXPECT_EQ(busy.running(), 1);
}

TEST(WorkerGovernor, KeepsRunningWhenTheOtherThreadsLeaveThemMoreThanOneCore) {
  // Two workers beside one more thread of the same session on two cores: each gets
  // two thirds of a core (wait 1/3), 1.33 cores between them: more than one worker.
  ScriptedMachine m;
  WorkerGovernor g = m.Governor(2);
  for (int i = 0; i < 10; ++i) {
    m.Pass(500, 2.0 * 2 / 3, 2.0 / 3);
    EXPECT_TRUE(g.MayRun(1));
  }
}

TEST(WorkerGovernor, CalibrationDecidesBeforeTheLoop) {
  for (const double wait : {0.5, 0.05}) {  // one core for both workers; free cores
    ScriptedMachine m;
    int reads = 0;
    WorkerGovernorOptions options;
    options.calibration = milliseconds(1);
    WorkerGovernor g(
        2, options,
        [&]() -> std::optional<SchedulerTimes> {
          // Two spinners, runnable for 20 ms each, between the calibration's reads.
          if (++reads == 3) {
            m.times.run_ns += 2 * 20e6 * (1 - wait);
            m.times.wait_ns += 2 * 20e6 * wait;
          }
          return m.times;
        },
        [&] { return m.now; });
    g.Calibrate();
    EXPECT_EQ(reads, 3);
    EXPECT_EQ(g.MayRun(1), wait < 0.4) << wait;
    EXPECT_EQ(g.parks(), wait < 0.4 ? 0 : 1);
  }
}

TEST(WorkerGovernor, IgnoresAWindowWhoseThreadsEndedAndTookTheirTimes) {
  ScriptedMachine m;
  WorkerGovernor g = m.Governor(2);
  m.Pass(500, 1.0, 1.0);
  m.times.wait_ns -= 2e9;  // a thread that had waited long ended meanwhile
  EXPECT_TRUE(g.MayRun(1));
  m.Pass(500, 1.0, 1.0);  // the next window is whole again: parked
  EXPECT_FALSE(g.MayRun(1));
}

TEST(WorkerGovernor, RunsEveryWorkerWithoutSchedulerTimesOrWithOneWorker) {
  ScriptedMachine m;
  m.readable = false;
  WorkerGovernor blind = m.Governor(2);
  m.Pass(500, 1.0, 1.0);
  EXPECT_TRUE(blind.MayRun(1));
  m.readable = true;
  WorkerGovernor one = m.Governor(1);
  m.Pass(500, 1.0, 1.0);
  EXPECT_TRUE(one.MayRun(0));
  EXPECT_EQ(one.parks(), 0);
}

TEST(ProcessSchedulerTimes, CountTheTimeThisThreadSpendsOnACore) {
  const std::optional<SchedulerTimes> before = ProcessSchedulerTimes();
  if (!before) GTEST_SKIP() << "no /proc/self/task/*/schedstat here";
  // Work until this thread's own CPU clock (a second account of the same time) says
  // 200 ms: on a busy machine that takes longer, the on-core time stays the same.
  timespec start{}, now{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &start);
  double spent = 0;
  while (spent < 0.2) {
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &now);
    spent = (now.tv_sec - start.tv_sec) + 1e-9 * (now.tv_nsec - start.tv_nsec);
  }
  const std::optional<SchedulerTimes> after = ProcessSchedulerTimes();
  ASSERT_TRUE(after);
  EXPECT_GE(after->run_ns - before->run_ns, 0.18e9);
  EXPECT_GE(after->wait_ns, before->wait_ns);
}

}  // namespace
}  // namespace handlabel
