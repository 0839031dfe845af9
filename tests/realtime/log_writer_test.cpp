#include "pneumid/realtime/log_writer.hpp"

#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <fstream>
#include <string>
#include <thread>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <matio.h>

#include "pneumid/common/check.hpp"

namespace pneumid {
namespace {

using ::testing::HasSubstr;

std::string TempPath(const std::string& name) {
  return std::string(PNEUMID_BINARY_DIR) + "/realtime_test_" + name;
}

std::vector<std::string> Lines(const std::string& path) {
  std::ifstream in(path);
  std::vector<std::string> lines;
  for (std::string l; std::getline(in, l);) lines.push_back(l);
  return lines;
}

LogRecord Rec(std::int64_t k) {
  LogRecord r;
  r.k = k;
  r.t = 0.01 * static_cast<double>(k);
  r.u = 50.0;
  r.y = static_cast<double>(k);
  r.r = 100.0;
  return r;
}

TEST(LogWriter, CsvHeaderRowsAndReservedStatistics) {
  const std::string path = TempPath("writer.csv");
  {
    LogWriter w(path, {{"controller", "dmc P=126\nM=5"}, {"period", "0.01"}});
    for (int k = 0; k < 1000; ++k) w.Push(Rec(k));
    w.Close("1000 samples, 0 overruns", "completed");
    EXPECT_EQ(w.written(), 1000);
    EXPECT_EQ(w.dropped(), 0);
  }
  const auto lines = Lines(path);
  ASSERT_EQ(lines.size(), 6u + 1000u);
  EXPECT_EQ(lines[0], "# pneumid real-time log");
  EXPECT_EQ(lines[1], "# controller: dmc P=126 M=5");  // newlines flattened
  EXPECT_EQ(lines[2], "# period: 0.01");
  EXPECT_THAT(lines[3], ::testing::StartsWith("# timing: 1000 samples, 0 overruns"));
  EXPECT_THAT(lines[4], ::testing::StartsWith("# stop: completed"));
  EXPECT_EQ(lines[5], "t,u,y,r,u_ctrl,aux,jitter_us,compute_us,flags,fault");
  EXPECT_EQ(lines[6], "0.000000,50,0,100,0,0,0.0,0.0,0,");
  EXPECT_THAT(lines.back(), ::testing::StartsWith("9.990000,50,999,"));
}

TEST(LogWriter, DatasetFormatHasOnlyTimeInputOutput) {
  const std::string path = TempPath("writer_dataset.csv");
  LogWriterOptions o;
  o.format = LogFormat::kDataset;
  LogWriter w(path, {}, o);
  for (int k = 0; k < 3; ++k) w.Push(Rec(k));
  w.Close();
  const auto lines = Lines(path);
  ASSERT_EQ(lines.size(), 4u + 3u);
  EXPECT_EQ(lines[3], "t,u,y");
  EXPECT_EQ(lines[6], "0.020000,50,2");
}

TEST(LogWriter, FullBufferDropsAndCountsInsteadOfBlocking) {
  const std::string path = TempPath("writer_full.csv");
  LogWriterOptions o;
  o.capacity = 16;
  LogWriter w(path, {}, o);
  // Far more than the buffer holds, faster than the writer formats lines:
  // records are dropped (a writer that blocked the loop would drop none), and
  // written + dropped accounts for every record.
  for (int k = 0; k < 100000; ++k) w.Push(Rec(k));
  const std::int64_t dropped_while_pushing = w.dropped();
  w.Close();
  EXPECT_GT(dropped_while_pushing, 0);
  EXPECT_EQ(w.dropped(), dropped_while_pushing);  // Close() drains, it drops nothing
  EXPECT_GT(w.written(), 0);
  EXPECT_EQ(w.written() + w.dropped(), 100000);
}

TEST(LogWriter, LiveRingGetsACopyOfEachRecordAndDropsWhenFull) {
  const std::string path = TempPath("writer_live.csv");
  SpscRingBuffer<LogRecord> live(8);
  LogWriterOptions o;
  o.live = &live;
  LogWriter w(path, {}, o);
  for (int k = 0; k < 20; ++k) w.Push(Rec(k));  // nobody drains: the ring fills up
  w.Close();
  EXPECT_EQ(w.written(), 20);  // the log is not affected
  EXPECT_EQ(w.dropped(), 0);
  ASSERT_EQ(live.size(), live.capacity());
  LogRecord r;
  for (std::size_t k = 0; k < live.capacity(); ++k) {
    ASSERT_TRUE(live.TryPop(&r));
    EXPECT_EQ(r.k, static_cast<std::int64_t>(k));  // the first ones, in order
  }
}

TEST(LogWriter, MatFileHoldsTheColumns) {
  const std::string path = TempPath("writer.mat");
  LogWriterOptions o;
  o.format = LogFormat::kMat;
  {
    LogWriter w(path, {{"controller", "pid"}}, o);
    for (int k = 0; k < 10; ++k) w.Push(Rec(k));
    w.Close("10 samples", "completed");
  }
  mat_t* mat = Mat_Open(path.c_str(), MAT_ACC_RDONLY);
  ASSERT_NE(mat, nullptr);
  matvar_t* y = Mat_VarRead(mat, "y");
  ASSERT_NE(y, nullptr);
  EXPECT_EQ(y->dims[0], 10u);
  EXPECT_EQ(static_cast<const double*>(y->data)[9], 9.0);
  Mat_VarFree(y);
  matvar_t* h = Mat_VarRead(mat, "header");
  ASSERT_NE(h, nullptr);
  const std::string text(static_cast<const char*>(h->data), h->dims[1]);
  EXPECT_THAT(text, HasSubstr("timing: 10 samples"));
  Mat_VarFree(h);
  Mat_Close(mat);
}

TEST(LogWriter, UnwritablePathIsADataError) {
  try {
    LogWriter w("/nonexistent-dir/x.csv", {});
    FAIL();
  } catch (const DataError& e) {
    EXPECT_THAT(e.what(), HasSubstr("/nonexistent-dir/x.csv"));
  }
}

// After SIGKILL at most the last flush interval is missing: a child logs 500 records,
// waits 3 flush intervals without closing, and is killed.
TEST(LogWriter, PeriodicFlushSurvivesSigkill) {
  const std::string path = TempPath("writer_kill.csv");
  const pid_t pid = fork();
  ASSERT_GE(pid, 0);
  if (pid == 0) {
    LogWriterOptions o;
    o.flush_interval = 0.05;
    auto* w = new LogWriter(path, {}, o);
    for (int k = 0; k < 500; ++k) w->Push(Rec(k));
    std::this_thread::sleep_for(std::chrono::seconds(30));  // killed long before
    _exit(0);
  }
  // Wait (at most 10 s, for a loaded machine) until the flushed rows are all there; without
  // the periodic flush the last rows would stay in the child's stdio buffer.
  for (int i = 0; i < 200 && Lines(path).size() < 504u; ++i)
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  kill(pid, SIGKILL);
  int status = 0;
  waitpid(pid, &status, 0);
  ASSERT_TRUE(WIFSIGNALED(status));
  const auto lines = Lines(path);
  ASSERT_EQ(lines.size(), 4u + 500u);  // 4 header lines, every record
  EXPECT_THAT(lines.back(), ::testing::StartsWith("4.990000,"));
}

}  // namespace
}  // namespace pneumid
