#include "io/files.h"

#include <gtest/gtest.h>
#include <sys/stat.h>

#include <csignal>
#include <filesystem>
#include <fstream>
#include <string>
#include <thread>

#include "core/check.h"
#include "core/temp_dir.h"

namespace jvl::io {
namespace {

namespace fs = std::filesystem;

class FilesTest : public ::testing::Test {
 protected:
  std::string Path(const std::string& name) const { return dir_.Path(name); }
  TempDir dir_{"jvl_files"};
};

TEST_F(FilesTest, ReadTextFileReturnsEveryByte) {
  // Binary content with NUL bytes, longer than one read chunk and not a multiple of it.
  std::string bytes;
  for (int i = 0; i < 200003; ++i) bytes.push_back(static_cast<char>((i * 131 + 7) % 256));
  {
    std::ofstream out(Path("bin"), std::ios::binary);
    out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  }
  EXPECT_EQ(ReadTextFile(Path("bin")), bytes);
  { std::ofstream out(Path("empty"), std::ios::binary); }
  EXPECT_EQ(ReadTextFile(Path("empty")), "");
}

TEST_F(FilesTest, ReadTextFileReadsAStreamOfUnknownLength) {
  // A FIFO has no size: it is read until its writer closes it.
  const std::string fifo = Path("fifo");
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  const std::string text(100000, 'x');
  std::signal(SIGPIPE, SIG_IGN);  // A reader that fails must fail the test, not kill it.
  std::thread writer([&] {
    std::ofstream out(fifo, std::ios::binary);
    out << text << "end";
  });
  std::string read;
  try {
    read = ReadTextFile(fifo);
  } catch (const Error& e) {
    ADD_FAILURE() << e.message();
    std::ifstream drain(fifo, std::ios::binary);  // Lets a writer still waiting to open finish.
  }
  writer.join();
  EXPECT_EQ(read, text + "end");
}

TEST_F(FilesTest, ReadTextFileOfAMissingFileSaysSo) {
  try {
    ReadTextFile(Path("missing"));
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_NE(e.message().find("cannot open file"), std::string::npos) << e.message();
  }
}

}  // namespace
}  // namespace jvl::io
