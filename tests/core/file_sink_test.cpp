#include "pinball/core/file_sink.h"

#include <gtest/gtest.h>
#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <fstream>
#include <iterator>
#include <string>
#include <thread>

namespace pinball {
namespace {

std::string read_all(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// A pipe's write end opened by path, as `--can-log /dev/stdout | reader` would.
std::string pipe_path(int fd) { return "/proc/self/fd/" + std::to_string(fd); }

TEST(FileSink, WritesTruncatesAndAppends) {
  const std::string path = ::testing::TempDir() + "/file_sink_" + std::to_string(getpid()) + ".txt";
  {
    FileSink sink(path);
    const SinkWrite w = sink.write("old text\n", 9);
    EXPECT_EQ(w.bytes, 9u);
    EXPECT_EQ(w.error, 0);
  }
  {
    FileSink sink(path);
    EXPECT_EQ(sink.write("one\n", 4).bytes, 4u);
    EXPECT_EQ(sink.close(), 0);
    EXPECT_EQ(sink.close(), 0);  // idempotent
  }
  {
    FileSink sink(path, true);
    EXPECT_EQ(sink.write("two\n", 4).bytes, 4u);
  }
  EXPECT_EQ(read_all(path), "one\ntwo\n");
  std::remove(path.c_str());
  try {
    const FileSink refused("/nonexistent-dir/x.log");
    FAIL();
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent-dir/x.log"), std::string::npos) << e.what();
  }
}

TEST(FileSink, AFullDiskIsAnErrorAndTheSinkStaysUsable) {
  FileSink sink("/dev/full");
  for (int i = 0; i < 2; ++i) {
    const SinkWrite w = sink.write("line\n", 5);
    EXPECT_EQ(w.bytes, 0u);
    EXPECT_EQ(w.error, ENOSPC);
    EXPECT_FALSE(sink.gone());  // a disk may get room again
  }
}

TEST(FileSink, APipeNobodyReadsWaitsOnlyUntilTheCallerGivesUp) {
  int fds[2];
  ASSERT_EQ(pipe(fds), 0);
  FileSink sink(pipe_path(fds[1]));
  const std::string block(1 << 20, 'x');  // more than any pipe holds
  int asked = 0;
  const auto t0 = std::chrono::steady_clock::now();
  const SinkWrite w = sink.write(block.data(), block.size(), [&] { return ++asked == 3; }, 0.01);
  const double waited_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  EXPECT_EQ(w.error, ETIMEDOUT);
  EXPECT_GT(w.bytes, 0u);  // what the pipe holds
  EXPECT_LT(w.bytes, block.size());
  EXPECT_EQ(asked, 3);
  EXPECT_LT(waited_s, 1.0);
  // Once the caller has given up, a further write does not wait at all.
  const auto t1 = std::chrono::steady_clock::now();
  EXPECT_EQ(sink.write(block.data(), block.size(), [] { return true; }, 10.0).error, ETIMEDOUT);
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - t1).count(), 1.0);
  ::close(fds[0]);
  ::close(fds[1]);
}

TEST(FileSink, APipeWhoseReaderLeftIsGoneWithoutKillingTheProcess) {
  // SIGPIPE keeps its default action (death) in this process; the writing thread blocks it.
  int fds[2];
  ASSERT_EQ(pipe(fds), 0);
  SinkWrite first, second;
  bool gone = false;
  std::thread writer([&] {
    block_sigpipe_in_this_thread();
    FileSink sink(pipe_path(fds[1]));
    ::close(fds[0]);
    first = sink.write("line\n", 5);
    second = sink.write("line\n", 5);
    gone = sink.gone();
  });
  writer.join();
  EXPECT_EQ(first.error, EPIPE);
  EXPECT_EQ(first.bytes, 0u);
  EXPECT_EQ(second.error, EPIPE);
  EXPECT_TRUE(gone);
  ::close(fds[1]);
}

// A named pipe with no reader is refused at once: opening it would wait for one for good.
TEST(FileSink, ANamedPipeNobodyReadsIsRefusedNotWaitedOn) {
  const std::string fifo = ::testing::TempDir() + "/file_sink_fifo_" + std::to_string(getpid());
  std::remove(fifo.c_str());
  ASSERT_EQ(mkfifo(fifo.c_str(), 0600), 0);
  try {
    FileSink sink(fifo);
    ADD_FAILURE() << "a named pipe with no reader was opened";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("a named pipe that nobody reads yet"), std::string::npos) << e.what();
  }
  const int reader = ::open(fifo.c_str(), O_RDONLY | O_NONBLOCK);
  ASSERT_GE(reader, 0);
  EXPECT_NO_THROW(FileSink sink(fifo));
  ::close(reader);
  std::remove(fifo.c_str());
}

// stderr's messages on a pipe nobody drains: dropped at once, never waited on.
TEST(WriteIfReady, TakesWhatTheDescriptorTakesAtOnceAndDropsTheRest) {
  int fds[2];
  ASSERT_EQ(pipe(fds), 0);
  EXPECT_TRUE(write_if_ready(fds[1], "one line\n"));
  const std::string page(1 << 20, 'x');  // more than any pipe holds
  const auto start = std::chrono::steady_clock::now();
  EXPECT_FALSE(write_if_ready(fds[1], page));
  EXPECT_LT(std::chrono::steady_clock::now() - start, std::chrono::seconds(1)) << "it waited";
  EXPECT_FALSE(write_if_ready(fds[1], "another\n")) << "a full pipe takes nothing";
  char head[9] = {};
  ASSERT_EQ(read(fds[0], head, 9), 9);
  EXPECT_EQ(std::string(head, 9), "one line\n");
  close(fds[0]);
  close(fds[1]);
}

}  // namespace
}  // namespace pinball
