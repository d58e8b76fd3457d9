// SPDX-License-Identifier: Apache-2.0
// The one check every reader makes of its input (core/file_io.h: check_input_file, read_file), the ceilings on
// images read (core/limits.h: check_image_size), names from input files that become file names, outputs that
// must differ, error text kept to one line, and directory outputs that appear whole.
#include <gtest/gtest.h>

#include <sys/stat.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <thread>

#include "core/error.h"
#include "core/file_io.h"
#include "core/limits.h"
#include "tests/core/spectral_exr_fixtures.h"

namespace ct {
namespace {

namespace fs = std::filesystem;

std::string message_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  }
  return "(no InputError)";
}

TEST(CheckInputFile, RegularFilesPassStreamsOnlyWhereReadInOrder) {
  test::TempDir dir;
  std::ofstream(dir.file("a.json")) << "{}";
  EXPECT_EQ(check_input_file(dir.file("a.json"), InputAccess::Seekable), 2u);
  EXPECT_EQ(check_input_file("/dev/null", InputAccess::Sequential), 0u);
  ASSERT_EQ(::mkfifo(dir.file("pipe").c_str(), 0600), 0);
  EXPECT_EQ(message_of([&] { check_input_file(dir.file("pipe"), InputAccess::Seekable); }),
            dir.file("pipe").string() + ": is a FIFO; this file is read only from a regular file");
  EXPECT_EQ(message_of([&] { check_input_file("/dev/zero", InputAccess::Seekable); }),
            "/dev/zero: is a character device; this file is read only from a regular file");
  EXPECT_EQ(message_of([&] { check_input_file(dir.path(), InputAccess::Sequential); }),
            dir.path().string() + ": is a directory, not a file");
  EXPECT_EQ(message_of([&] { check_input_file(dir.file("none"), InputAccess::Sequential); }),
            dir.file("none").string() + ": cannot open file");
  EXPECT_EQ(message_of([&] { check_input_file(dir.file("a.json"), InputAccess::Sequential, 1); }),
            dir.file("a.json").string() + ": 2 bytes, more than the limit of 1 bytes (0 MiB) for this kind of file");
}

TEST(ReadFile, StreamsAreBoundedAndAFifoWithoutWriterIsNoWait) {
  test::TempDir dir;
  EXPECT_EQ(message_of([&] { read_file("/dev/zero", 1000); }),
            "/dev/zero: more than the limit of 1000 bytes (0 MiB) for this kind of file");
  EXPECT_EQ(read_file("/dev/null"), "");
  const fs::path fifo = dir.file("pipe");
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  const auto start = std::chrono::steady_clock::now();
  EXPECT_EQ(message_of([&] { read_file(fifo); }),
            fifo.string() + ": is a FIFO that nothing writes to (nothing arrived within 2 s)");
  EXPECT_LT(std::chrono::steady_clock::now() - start, std::chrono::seconds(5));
  // With a writer, what it writes — more than a pipe's buffer — is read to its end.
  const std::string text(200000, 'x');
  std::thread writer([&] { std::ofstream(fifo) << text; });
  EXPECT_EQ(read_file(fifo), text);
  writer.join();
}

TEST(CheckFileName, OnlyOnePlainComponentPasses) {
  EXPECT_NO_THROW(check_file_name("direct light", "variant"));
  EXPECT_NO_THROW(check_file_name("..a", "variant"));
  for (const char* bad : {"", ".", "..", "a/b", "../x", "/abs", "a\nb", "a\x7f"})
    EXPECT_NE(message_of([&] { check_file_name(bad, "variant"); }).find("cannot be a file name"), std::string::npos) << bad;
  EXPECT_EQ(message_of([&] { check_file_name("a/../../x", "variant"); }),
            R"(variant: "a/../../x" cannot be a file name: it holds a "/"; names are written inside the output directory)");
  EXPECT_EQ(message_of([&] { check_file_name(std::string(256, 'n'), ""); }).substr(259),
            "cannot be a file name: it is longer than 255 bytes");
}

TEST(CheckImageSize, TheBudgetAndTheFileBoundWhatAHeaderMayClaim) {
  EXPECT_NO_THROW(check_image_size("ok.png", 8000, 8000, 3, 200000, 1));  // 768 MB of floats, ratio 960
  EXPECT_EQ(message_of([] { check_image_size("big.png", 16000, 16000, 3); }),
            "big.png: image of 16000x16000 pixels, 3 channels: needs 3.07 GB as floats, more than the budget of 1 GiB "
            "for one image (about 89 megapixels of RGB)");
  EXPECT_EQ(message_of([] { check_image_size("lie.png", 4000, 4000, 3, 74, 1); }),
            "lie.png: image of 4000x4000 pixels, 3 channels: its header claims 48000000 bytes of samples, more than "
            "its 74 bytes can hold (at most 2048 each); the file is corrupt or cut short");
  // 16-bit samples count twice.
  EXPECT_NO_THROW(check_image_size("a.tif", 100, 100, 1, 10, 1));
  EXPECT_THROW(check_image_size("a.tif", 200, 100, 1, 10, 2), InputError);
}

TEST(CheckDistinctOutputs, OneFileUnderTwoNamesIsRefused) {
  test::TempDir dir;
  EXPECT_NO_THROW(check_distinct_outputs({dir.file("a.json"), dir.file("b.json"), ""}));
  EXPECT_EQ(message_of([&] { check_distinct_outputs({dir.file("a.json"), dir.path() / "." / "a.json"}); }),
            (dir.path() / "." / "a.json").string() + ": is the same file as the output " + dir.file("a.json").string() +
                "; each output needs a file of its own");
  std::ofstream(dir.file("real.json")) << "x";
  fs::create_symlink("real.json", dir.file("link.json"));
  fs::create_hard_link(dir.file("real.json"), dir.file("hard.json"));
  EXPECT_THROW(check_distinct_outputs({dir.file("link.json"), dir.file("real.json")}), InputError);
  EXPECT_THROW(check_distinct_outputs({dir.file("hard.json"), dir.file("link.json")}), InputError);
}

TEST(CheckOutputFile, NamesLongerThanTheSystemTakesAreBadInput) {
  test::TempDir dir;
  EXPECT_NE(message_of([&] { check_output_file(dir.file(std::string(4097, 'a'))); }).find("the output path is"),
            std::string::npos);
  EXPECT_NE(message_of([&] { check_output_directory(dir.file(std::string(256, 'a'))); })
                .find("a name in the output path is 256 bytes long, more than the 255 the system takes"),
            std::string::npos);
}

TEST(OneLine, ControlCharactersAreEscapedAndTrailingBreaksDropped) {
  EXPECT_EQ(one_line("a\nb\tc\r\x01\x7f" "d\n\n"), R"(a\nb\tc\r\x01\x7fd)");
  EXPECT_EQ(one_line("ünïcode stays"), "ünïcode stays");
}

TEST(StagedDirectory, TheSummaryIsMovedLastIntoAnExistingDirectory) {
  test::TempDir dir;
  const fs::path target = dir.file("out");
  fs::create_directories(target);
  std::ofstream(target / "keep.txt") << "kept";
  {
    StagedDirectory staged(target, {"a_summary.json"});
    std::ofstream(staged.path() / "a_summary.json") << "new summary";
    std::ofstream(staged.path() / "z_page.html") << "new page";
    // A page that cannot be moved in (a directory in its way) stops the commit before the summary moves.
    fs::create_directories(target / "z_page.html");
    EXPECT_THROW(staged.commit(), InputError);
  }
  EXPECT_FALSE(fs::exists(target / "a_summary.json"));
  fs::remove(target / "z_page.html");
  {
    StagedDirectory staged(target, {"a_summary.json"});
    std::ofstream(staged.path() / "a_summary.json") << "new summary";
    std::ofstream(staged.path() / "z_page.html") << "new page";
    staged.commit();
  }
  EXPECT_TRUE(fs::is_regular_file(target / "a_summary.json"));
  EXPECT_TRUE(fs::is_regular_file(target / "z_page.html"));
  EXPECT_TRUE(fs::is_regular_file(target / "keep.txt"));
}

}  // namespace
}  // namespace ct
