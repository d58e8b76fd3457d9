// SPDX-License-Identifier: Apache-2.0
// Outputs that never destroy inputs or replace special files (core/file_io.h), and JSON input whose numbers
// no double holds (core/json_input.h).
#include <gtest/gtest.h>

#include <sys/stat.h>
#include <sys/sysmacros.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include <fmt/core.h>

#include "core/error.h"
#include "core/file_io.h"
#include "core/json_input.h"
#include "tests/core/spectral_exr_fixtures.h"

namespace ct {
namespace {

namespace fs = std::filesystem;

void write_text(const fs::path& path, const std::string& text) { std::ofstream(path, std::ios::binary) << text; }

std::string text_of(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

void write_atomically(const fs::path& target, const std::string& text) {
  AtomicFile out(target);
  ASSERT_EQ(::write(out.descriptor(), text.data(), text.size()), static_cast<ssize_t>(text.size()));
  out.commit();
}

// The message of the InputError that `f` throws ("" if it throws none).
template <class F>
std::string input_error(F f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

// ---- same_file and check_not_an_input ---------------------------------------------------------------

TEST(SameFile, HardLinksDotSpellingsAndSymbolicLinksNameOneFile) {
  test::TempDir dir;
  const fs::path a = dir.file("a.exr");
  write_text(a, "spectral render");
  write_text(dir.file("copy.exr"), "spectral render");
  fs::create_hard_link(a, dir.file("hard.exr"));
  fs::create_symlink(a, dir.file("soft.exr"));
  fs::create_symlink("soft.exr", dir.file("soft2.exr"));  // relative, and a link to a link

  EXPECT_TRUE(same_file(a, a));
  EXPECT_TRUE(same_file(a, dir.path() / "." / "a.exr"));
  EXPECT_TRUE(same_file(a, dir.path() / ".." / dir.path().filename() / "a.exr"));
  EXPECT_TRUE(same_file(a, dir.file("hard.exr")));
  EXPECT_TRUE(same_file(a, dir.file("soft.exr")));
  EXPECT_TRUE(same_file(dir.file("soft2.exr"), a));
  EXPECT_FALSE(same_file(a, dir.file("copy.exr")));  // equal bytes, another file
  EXPECT_FALSE(same_file(a, dir.file("missing.exr")));
  EXPECT_FALSE(same_file(dir.file("missing.exr"), dir.file("missing.exr")));

  const fs::path out = dir.file("hard.exr");
  EXPECT_EQ(input_error([&] { check_not_an_input(out, {dir.file("copy.exr"), a}); }),
            fmt::format("{}: is the same file as the input {}; writing the output would destroy the input",
                        out.string(), a.string()));
  EXPECT_EQ(input_error([&] { check_not_an_input(dir.file("new.exr"), {a}); }), "");
}

// ---- check_output_file and check_output_directory ---------------------------------------------------

TEST(CheckOutputFile, RefusesDirectoriesSpecialFilesInputsAndMissingDirectories) {
  test::TempDir dir;
  const fs::path input = dir.file("scene.json");
  write_text(input, "{}");
  ASSERT_EQ(::mkfifo(dir.file("pipe").c_str(), 0600), 0);
  fs::create_symlink("pipe", dir.file("to_pipe"));
  fs::create_directory(dir.file("sub"));

  EXPECT_EQ(input_error([&] { check_output_file(dir.file("new.exr"), {input}); }), "");
  write_text(dir.file("old.exr"), "x");
  EXPECT_EQ(input_error([&] { check_output_file(dir.file("old.exr"), {input}); }), "");  // replaced: fine

  const std::string p = dir.path().string();
  EXPECT_EQ(input_error([&] { check_output_file(dir.file("sub"), {}); }),
            p + "/sub: is a directory; the output must be a file name");
  EXPECT_EQ(input_error([&] { check_output_file(dir.file("pipe"), {}); }),
            p + "/pipe: is a FIFO; outputs are written only as regular files, never in place of a special file");
  EXPECT_EQ(input_error([&] { check_output_file(dir.file("to_pipe"), {}); }),
            p + "/to_pipe: links to " + p +
                "/pipe, which is a FIFO; outputs are written only as regular files, never in place of a special file");
  EXPECT_EQ(input_error([&] { check_output_file(dir.file("no/such/out.exr"), {}); }),
            p + "/no/such/out.exr: directory " + p + "/no/such does not exist");
  EXPECT_EQ(input_error([&] { check_output_file(dir.path() / "." / "scene.json", {input}); }),
            p + "/./scene.json: is the same file as the input " + input.string() +
                "; writing the output would destroy the input");
  EXPECT_TRUE(fs::is_fifo(dir.file("pipe")));
}

TEST(CheckOutputDirectory, RefusesFilesAndInputs) {
  test::TempDir dir;
  const fs::path image = dir.file("photo.png");
  write_text(image, "png");
  EXPECT_EQ(input_error([&] { check_output_directory(dir.file("analysis"), {image}); }), "");
  EXPECT_EQ(input_error([&] { check_output_directory(dir.path(), {image}); }), "");
  EXPECT_EQ(input_error([&] { check_output_directory(image, {image}); }),
            image.string() + ": is the same file as the input " + image.string() +
                "; writing the output would destroy the input");
  write_text(dir.file("notes.txt"), "");
  EXPECT_EQ(input_error([&] { check_output_directory(dir.file("notes.txt"), {image}); }),
            dir.file("notes.txt").string() + ": exists and is not a directory");
  EXPECT_EQ(input_error([&] { check_output_directory(dir.file("a/b"), {}); }),
            dir.file("a/b").string() + ": directory " + dir.file("a").string() + " does not exist");
}

// ---- AtomicFile: links followed, special files never replaced ---------------------------------------

TEST(AtomicFile, ASymbolicLinkIsFollowedAndKept) {
  test::TempDir dir;
  fs::create_directory(dir.file("renders"));
  write_text(dir.file("renders/today.exr"), "old");
  fs::create_symlink("renders/today.exr", dir.file("latest.exr"));
  write_atomically(dir.file("latest.exr"), "new");
  EXPECT_TRUE(fs::is_symlink(fs::symlink_status(dir.file("latest.exr"))));
  EXPECT_EQ(fs::read_symlink(dir.file("latest.exr")), "renders/today.exr");
  EXPECT_EQ(text_of(dir.file("renders/today.exr")), "new");
  // Nothing left beside either.
  EXPECT_EQ(std::distance(fs::directory_iterator(dir.path()), fs::directory_iterator()), 2);
  EXPECT_EQ(std::distance(fs::directory_iterator(dir.file("renders")), fs::directory_iterator()), 1);

  // A dangling link: its target is created.
  fs::create_symlink("made.exr", dir.file("dangling.exr"));
  write_atomically(dir.file("dangling.exr"), "made");
  EXPECT_TRUE(fs::is_symlink(fs::symlink_status(dir.file("dangling.exr"))));
  EXPECT_EQ(text_of(dir.file("made.exr")), "made");

  // A loop of links is an InputError, not a hang.
  fs::create_symlink("loop_b", dir.file("loop_a"));
  fs::create_symlink("loop_a", dir.file("loop_b"));
  EXPECT_EQ(input_error([&] { AtomicFile out(dir.file("loop_a")); }),
            dir.file("loop_a").string() + ": too many levels of symbolic links");
}

// A file written over keeps its permissions, as one cp writes over does (a private 0600 file stays private).
TEST(AtomicFile, AReplacedFileKeepsItsPermissions) {
  test::TempDir dir;
  write_text(dir.file("private.json"), "old");
  fs::permissions(dir.file("private.json"), fs::perms::owner_read | fs::perms::owner_write);
  write_atomically(dir.file("private.json"), "new");
  EXPECT_EQ(text_of(dir.file("private.json")), "new");
  EXPECT_EQ(fs::status(dir.file("private.json")).permissions() & fs::perms::all, fs::perms::owner_read | fs::perms::owner_write);
}

TEST(AtomicFile, AFifoADirectoryAndALinkToThemAreNeverReplaced) {
  test::TempDir dir;
  const fs::path fifo = dir.file("pipe");
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  fs::create_symlink(fifo, dir.file("link"));
  fs::create_directory(dir.file("sub"));
  EXPECT_NE(input_error([&] { AtomicFile out(fifo); }).find("pipe: is a FIFO"), std::string::npos);
  EXPECT_NE(input_error([&] { AtomicFile out(dir.file("link")); }).find("link: links to " + fifo.string() + ", which is a FIFO"),
            std::string::npos);
  EXPECT_EQ(input_error([&] { AtomicFile out(dir.file("sub")); }),
            dir.file("sub").string() + ": is a directory; the output must be a file name");
  EXPECT_THROW(write_file_atomically(fifo, "bytes"), InputError);
  EXPECT_TRUE(fs::is_fifo(fifo));
  EXPECT_TRUE(fs::is_symlink(fs::symlink_status(dir.file("link"))));
  EXPECT_TRUE(fs::is_directory(dir.file("sub")));
  EXPECT_EQ(std::distance(fs::directory_iterator(dir.path()), fs::directory_iterator()), 3);  // no temporary left
}

TEST(AtomicFile, ASpecialFileThatAppearsDuringTheWriteIsNotReplaced) {
  test::TempDir dir;
  const fs::path target = dir.file("out.exr");
  {
    AtomicFile out(target);
    ASSERT_EQ(::write(out.descriptor(), "x", 1), 1);
    ASSERT_EQ(::mkfifo(target.c_str(), 0600), 0);  // while a long render ran
    EXPECT_THROW(out.commit(), InputError);
  }
  EXPECT_TRUE(fs::is_fifo(target));
  EXPECT_EQ(std::distance(fs::directory_iterator(dir.path()), fs::directory_iterator()), 1);
}

TEST(AtomicFile, ADeviceIsNeverReplaced) {
  test::TempDir dir;
  // A device node of our own (the null device's numbers), not a real device path: needs CAP_MKNOD.
  const fs::path device = dir.file("null");
  if (::mknod(device.c_str(), S_IFCHR | 0666, makedev(1, 3)) != 0) {
    GTEST_SKIP() << "cannot create a device node here";
  }
  EXPECT_EQ(input_error([&] { AtomicFile out(device); }),
            device.string() +
                ": is a character device; outputs are written only as regular files, never in place of a special file");
  EXPECT_EQ(input_error([&] { check_output_file(device, {}); }),
            device.string() +
                ": is a character device; outputs are written only as regular files, never in place of a special file");
  EXPECT_TRUE(fs::is_character_file(device));
}

// ---- read_file -------------------------------------------------------------------------------------

TEST(ReadFile, ADirectoryIsCalledADirectory) {
  test::TempDir dir;
  EXPECT_EQ(input_error([&] { read_file(dir.path()); }), dir.path().string() + ": is a directory, not a file");
  EXPECT_EQ(input_error([&] { read_json(dir.path()); }), dir.path().string() + ": is a directory, not a file");
  EXPECT_EQ(input_error([&] { read_file(dir.file("missing")); }), dir.file("missing").string() + ": cannot open file");
}

// ---- JSON numbers beyond a double ------------------------------------------------------------------

TEST(ParseJson, ANumberNoDoubleHoldsIsNamedByPositionAndPath) {
  const std::string range = "is out of range (a finite number of magnitude below 1.8e308 is needed)";
  EXPECT_EQ(input_error([] { parse_json(R"({"a": {"b": 1e999}})", "s.json"); }),
            "s.json: line 1, column 13: a.b: number 1e999 " + range);
  EXPECT_EQ(input_error([] { parse_json("{\n  \"x\": [1, -1e999]\n}", "s.json"); }),
            "s.json: line 2, column 12: x[1]: number -1e999 " + range);
  EXPECT_EQ(input_error([] { parse_json("1E400", "s.json"); }), "s.json: line 1, column 1: number 1E400 " + range);
  // An integer too long for 64 bits is read as a double, and one beyond a double is refused the same way.
  const std::string huge = "1" + std::string(400, '0');
  EXPECT_EQ(input_error([&] { parse_json("[0, 0, " + huge + "]", "s.json"); }),
            "s.json: line 1, column 8: [2]: number " + huge.substr(0, 40) + "... " + range);
  // The largest finite numbers still parse.
  EXPECT_EQ(parse_json("[1.7976931348623157e308, -1e-999]", "s.json")[0].get<double>(), 1.7976931348623157e308);
  // Syntax errors and repeated keys are reported as before.
  EXPECT_EQ(input_error([] { parse_json(R"({"a": 1, "a": 2})", "s.json"); }), "s.json: a: key appears twice in one object");
  EXPECT_NE(input_error([] { parse_json("{\"a\": }", "s.json"); }).find("s.json: line 1, column 7: syntax error"),
            std::string::npos);
}

}  // namespace
}  // namespace ct
