// The output policy (model/io/files.h): atomic writes, sets of files written together, regular
// files only, symbolic links followed, never over an input, no write into a missing directory.
#include <sys/stat.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include <gtest/gtest.h>

#include "io/files.h"
#include "test_util.h"

using namespace shd;
using shd::testutil::errorOf;
namespace fs = std::filesystem;

namespace {

class Files : public testing::Test {
 protected:
  void SetUp() override { dir_ = testutil::freshTestDir("test_files"); }
  std::string path(const std::string& name) const { return (dir_ / name).string(); }
  static std::string read(const std::string& p) {
    std::ifstream in(p, std::ios::binary);
    std::ostringstream s;
    s << in.rdbuf();
    return s.str();
  }
  // The directory's entries: no temporary may be left behind.
  size_t entries() const { return testutil::dirEntries(dir_).size(); }
  fs::path dir_;
};

TEST_F(Files, WritesAndReplacesAtomically) {
  writeFileAtomic(path("a.txt"), "one");
  writeFileAtomic(path("a.txt"), "two");
  EXPECT_EQ(read(path("a.txt")), "two");
  EXPECT_EQ(entries(), 1u);
}

TEST_F(Files, FollowsASymbolicLinkAndKeepsIt) {
  writeFileAtomic(path("real.txt"), "old");
  fs::create_symlink("real.txt", path("link.txt"));
  writeFileAtomic(path("link.txt"), "new");
  EXPECT_TRUE(fs::is_symlink(path("link.txt")));
  EXPECT_EQ(read(path("real.txt")), "new");
  // A dangling link creates the file it names.
  fs::create_symlink("later.txt", path("dangling.txt"));
  writeFileAtomic(path("dangling.txt"), "made");
  EXPECT_EQ(read(path("later.txt")), "made");
}

TEST_F(Files, RefusesFifosDirectoriesAndDevices) {
  ASSERT_EQ(::mkfifo(path("fifo").c_str(), 0600), 0);
  EXPECT_NE(errorOf([&] { writeFileAtomic(path("fifo"), "x"); }).find("it is a FIFO"), std::string::npos);
  fs::create_directories(path("sub"));
  EXPECT_NE(errorOf([&] { writeFileAtomic(path("sub"), "x"); }).find("it is a directory"), std::string::npos);
  EXPECT_NE(errorOf([&] { outputTarget("/dev/null"); }).find("it is a character device"), std::string::npos);
  struct stat st {};
  ASSERT_EQ(::stat(path("fifo").c_str(), &st), 0);
  EXPECT_TRUE(S_ISFIFO(st.st_mode));  // still the FIFO
  EXPECT_EQ(entries(), 2u);           // no temporary left
}

TEST_F(Files, RefusesAnInputOfTheRunEvenThroughALink) {
  writeFileAtomic(path("scene.json"), "{}");
  fs::create_symlink("scene.json", path("alias.json"));
  {
    const RunInputs run;
    noteInput(path("scene.json"));
    const std::string e = errorOf([&] { writeFileAtomic(path("alias.json"), "overwritten"); });
    EXPECT_NE(e.find("is an input of this run"), std::string::npos) << e;
    EXPECT_EQ(read(path("scene.json")), "{}");
  }
  // After the run, and outside any run, the file is an ordinary output.
  writeFileAtomic(path("alias.json"), "rewritten");
  EXPECT_EQ(read(path("scene.json")), "rewritten");
  noteInput(path("scene.json"));  // no run: not recorded
  writeFileAtomic(path("scene.json"), "again");
  EXPECT_EQ(read(path("scene.json")), "again");
}

TEST_F(Files, RefusesAMissingDirectory) {
  const std::string e = errorOf([&] { writeFileAtomic(path("no/such/dir/x.txt"), "x"); });
  EXPECT_NE(e.find("no directory"), std::string::npos) << e;
  EXPECT_EQ(entries(), 0u);
}

// A set whose last file cannot be written touches none of the others and leaves no temporary.
TEST_F(Files, ASetIsWrittenWholeOrNotAtAll) {
  writeFileAtomic(path("image.png"), "old image");
  OutputFiles set;
  set.add(path("image.png"), "new image");
  set.add(path("stats.json"), "{}");
  set.add(path("missing/x.json"), "{}");
  EXPECT_NE(errorOf([&] { set.commit(); }).find("no directory"), std::string::npos);
  EXPECT_EQ(read(path("image.png")), "old image");
  EXPECT_FALSE(fs::exists(path("stats.json")));
  EXPECT_EQ(entries(), 1u);

  OutputFiles twice;
  twice.add(path("a.txt"), "1");
  twice.add(path("a.txt"), "2");
  EXPECT_NE(errorOf([&] { twice.commit(); }).find("writes it twice"), std::string::npos);
  EXPECT_EQ(entries(), 1u);

  OutputFiles good;
  good.add(path("image.png"), "new image");
  good.add(path("stats.json"), "{}");
  good.commit();
  EXPECT_EQ(read(path("image.png")), "new image");
  EXPECT_EQ(read(path("stats.json")), "{}");
}

}  // namespace
