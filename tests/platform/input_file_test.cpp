// platform/input_file.h: the one way an input is opened. Each refusal is immediate and says what
// the path is; text is read line by line within its bounds.
#include "platform/input_file.h"

#include <sys/stat.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <fstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

namespace plumb {
namespace {

std::string scratch(const std::string& name) {
  const std::string dir = testing::TempDir() + "plumb_input_file_" + std::to_string(::getpid());
  ::mkdir(dir.c_str(), 0755);
  const std::string path = dir + "/" + name;
  std::remove(path.c_str());
  return path;
}

void writeFile(const std::string& path, const std::string& text) {
  std::ofstream(path, std::ios::binary) << text;
}

TEST(InputFile, FifoIsRefusedWithoutBlocking) {
  const std::string path = scratch("fifo");
  ASSERT_EQ(::mkfifo(path.c_str(), 0600), 0);
  const auto start = std::chrono::steady_clock::now();
  InputFile file;
  const Status st = file.open(path, 1 << 20, "map");
  EXPECT_LT(std::chrono::steady_clock::now() - start, std::chrono::seconds(2));  // no writer: open() would hang
  ASSERT_FALSE(st.ok());
  EXPECT_NE(st.message().find("FIFO"), std::string::npos) << st.message();
  EXPECT_NE(st.message().find("map " + path), std::string::npos) << st.message();
}

TEST(InputFile, DeviceAndFolderAreRefused) {
  InputFile file;
  Status st = file.open("/dev/zero", 1 << 20, "camera file");
  ASSERT_FALSE(st.ok());
  EXPECT_NE(st.message().find("character device"), std::string::npos) << st.message();
  st = file.open("/", 1 << 20, "");
  ASSERT_FALSE(st.ok());
  EXPECT_NE(st.message().find("folder"), std::string::npos) << st.message();
}

TEST(InputFile, SizeIsBoundedBeforeReading) {
  const std::string path = scratch("big");
  writeFile(path, std::string(2000, 'x'));
  std::string bytes;
  const Status st = readInputFile(path, 1000, "trace file", &bytes);
  ASSERT_FALSE(st.ok());
  EXPECT_NE(st.message().find("beyond the limit of 1000 bytes"), std::string::npos) << st.message();
  EXPECT_TRUE(bytes.empty());
  ASSERT_TRUE(readInputFile(path, 2000, "trace file", &bytes).ok());
  EXPECT_EQ(bytes.size(), 2000u);
}

TEST(InputFile, SymlinkLoopAndMissingFileSayWhatTheyAre) {
  const std::string loop = scratch("loop");
  ASSERT_EQ(::symlink("loop", loop.c_str()), 0);
  InputFile file;
  Status st = file.open(loop, 1 << 20, "image file");
  ASSERT_FALSE(st.ok());
  EXPECT_NE(st.message().find("symlink loop"), std::string::npos) << st.message();
  st = requireRegularFile(loop, "image file");
  EXPECT_NE(st.message().find("symlink loop"), std::string::npos) << st.message();
  st = requireRegularFile(scratch("missing"), "image file");
  EXPECT_NE(st.message().find("missing"), std::string::npos) << st.message();
}

TEST(InputFile, LinesSkipTheByteOrderMarkAndStopEarly) {
  const std::string path = scratch("lines");
  writeFile(path, "\xEF\xBB\xBF" "first\r\nsecond\nthird\nfourth");
  std::vector<std::string> lines;
  ASSERT_TRUE(forEachInputLine(path, 1 << 20, "", [&](int number, const std::string& text, Status*) {
                EXPECT_EQ(number, int(lines.size()) + 1);
                lines.push_back(text);
                return lines.size() < 3;  // stop after three
              }).ok());
  ASSERT_EQ(lines.size(), 3u);
  EXPECT_EQ(lines[0], "first");  // no BOM, no '\r'
  EXPECT_EQ(lines[2], "third");
}

TEST(InputFile, LongLinesAndBinaryDataAreRefusedWithFileAndLine) {
  const std::string path = scratch("long");
  writeFile(path, "ok\n" + std::string(100, 'x') + "\n");
  Status st = forEachInputLine(path, 1 << 20, "", [](int, const std::string&, Status*) { return true; }, 50);
  ASSERT_FALSE(st.ok());
  EXPECT_NE(st.message().find(path + ":2: line longer than 50 bytes"), std::string::npos) << st.message();
  writeFile(path, std::string("a\0b\n", 4));
  st = forEachInputLine(path, 1 << 20, "", [](int, const std::string&, Status*) { return true; });
  ASSERT_FALSE(st.ok());
  EXPECT_NE(st.message().find("NUL"), std::string::npos) << st.message();
}

}  // namespace
}  // namespace plumb
