// The one atomic file writer and the one lock (io/atomic_file.hpp, io/file_lock.hpp): what
// every output of wheelins relies on.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <stdexcept>
#include <string>

#include "io_test_util.hpp"
#include "wheelins/io/atomic_file.hpp"
#include "wheelins/io/file_lock.hpp"
#include "wheelins/io/output_dir.hpp"
#include "wheelins/nav/types.hpp"
#include "wheelins/study/files.hpp"

namespace fs = std::filesystem;
using namespace wheelins;
using iotest::error_of;

namespace {
std::size_t entries(const fs::path& dir) {
  std::size_t n = 0;
  for ([[maybe_unused]] const auto& e : fs::directory_iterator(dir)) ++n;
  return n;
}
}  // namespace

TEST(AtomicFile, AppearsWholeAtCommitAndNotBefore) {
  iotest::ScratchDir dir;
  const fs::path file = dir / "sub" / "a.txt";
  {
    AtomicFile out(file, {});
    out.write("first ");
    out.write(std::string(200000, 'x'));
    EXPECT_FALSE(fs::exists(file));
    EXPECT_TRUE(fs::exists(out.temporary()));
    EXPECT_EQ(out.temporary().parent_path(), file.parent_path());
    out.commit();
    EXPECT_FALSE(fs::exists(out.temporary()));
  }
  EXPECT_EQ(iotest::read_text_file(file), "first " + std::string(200000, 'x'));
  EXPECT_EQ(entries(dir / "sub"), 1u);
}

TEST(AtomicFile, WithoutCommitNothingIsLeftAndTheOldFileStays) {
  iotest::ScratchDir dir;
  const fs::path file = dir / "a.txt";
  iotest::write_text(file, "old\n");
  EXPECT_HAS(error_of([&] {
               AtomicFile out(file, {});
               out.write("new, cut short");
               throw InputError("a failure part-way");
             }),
             "a failure part-way");
  EXPECT_EQ(iotest::read_text_file(file), "old\n");
  EXPECT_EQ(entries(dir.path()), 1u);
  // A chunk writer that fails half-way (a full disk): the same.
  try {
    write_file_atomic(file, std::string(300000, 'y'), {}, [](int fd, std::string_view chunk) {
      ASSERT_EQ(::write(fd, chunk.data(), chunk.size() / 2), static_cast<ssize_t>(chunk.size() / 2));
      throw std::runtime_error("disk full (simulated)");
    });
    ADD_FAILURE() << "the failing writer was not called";
  } catch (const std::runtime_error& e) {
    EXPECT_HAS(std::string(e.what()), "disk full (simulated)");
  }
  EXPECT_EQ(iotest::read_text_file(file), "old\n");
  EXPECT_EQ(entries(dir.path()), 1u);
}

TEST(AtomicFile, ReplacesOnlyWhenAskedAlsoAFileThatAppearedMeanwhile) {
  iotest::ScratchDir dir;
  const fs::path file = dir / "a.txt";
  iotest::write_text(file, "mine\n");
  EXPECT_HAS(error_of([&] { AtomicFile out(file, {false, {}}); }), "already exists; refusing to overwrite");
  write_file_atomic(file, "replaced\n");  // overwrite is the default
  EXPECT_EQ(iotest::read_text_file(file), "replaced\n");

  const fs::path later = dir / "b.txt";
  AtomicFile out(later, {false, {}});
  out.write("ours\n");
  iotest::write_text(later, "the user's, written meanwhile\n");
  EXPECT_HAS(error_of([&] { out.commit(); }), "already exists");
  EXPECT_EQ(iotest::read_text_file(later), "the user's, written meanwhile\n");
  EXPECT_FALSE(fs::exists(out.temporary()));
  EXPECT_HAS(error_of([&] { AtomicFile d(dir.path(), {}); }), "is a directory");
}

TEST(AtomicFile, TwoWritersOfOneFileNeverShareATemporary) {
  iotest::ScratchDir dir;
  const fs::path file = dir / "a.txt";
  AtomicFile a(file, {}), b(file, {});
  EXPECT_NE(a.temporary(), b.temporary());
  a.write("a\n");
  b.write("b\n");
  a.commit();
  EXPECT_EQ(iotest::read_text_file(file), "a\n");
  b.commit();
  EXPECT_EQ(iotest::read_text_file(file), "b\n");
  // A study's temporaries are hidden and carry the host (several machines share a directory).
  const AtomicFileOptions shared = study::shared_file(file);
  EXPECT_EQ(shared.temporary.filename().string().rfind(".a.txt.tmp-" + study::host_name() + "-", 0), 0u);
  EXPECT_HAS(error_of([&] {
               AtomicFile taken(file, {true, a.temporary()});
               AtomicFile again(file, {true, a.temporary()});
             }),
             "cannot create: File exists");
}

TEST(AtomicFile, MoveIntoPlaceRefusesAnExistingFileUnlessToldAndLeavesNoTemporary) {
  iotest::ScratchDir dir;
  iotest::write_text(dir / "plot.png", "the user's\n");
  iotest::write_text(dir / "new.partial", "rendered\n");
  EXPECT_HAS(error_of([&] { move_into_place(dir / "new.partial", dir / "plot.png", false); }), "already exists");
  EXPECT_FALSE(fs::exists(dir / "new.partial"));
  EXPECT_EQ(iotest::read_text_file(dir / "plot.png"), "the user's\n");
  iotest::write_text(dir / "new.partial", "rendered\n");
  move_into_place(dir / "new.partial", dir / "plot.png", true);
  EXPECT_EQ(iotest::read_text_file(dir / "plot.png"), "rendered\n");
}

TEST(FileLock, ASecondHolderWaitsOrIsToldAndTheLockGoesWithItsHolder) {
  iotest::ScratchDir dir;
  const fs::path file = dir / "data.lock";
  {
    FileLock first(file, FileLock::Wait::kUntilFree);
    EXPECT_TRUE(first.locked());
    EXPECT_TRUE(fs::exists(file));  // a lock file is created
    const FileLock second(file, FileLock::Wait::kNo);
    EXPECT_EQ(second.state(), FileLock::State::kHeldElsewhere);
    EXPECT_FALSE(second.locked());
    first.release();
    const FileLock third(file, FileLock::Wait::kNo);
    EXPECT_TRUE(third.locked());
  }
  const FileLock directory(dir.path(), FileLock::Wait::kNo);  // a directory is locked as it is
  EXPECT_TRUE(directory.locked());
  EXPECT_HAS(error_of([&] { FileLock missing(dir / "no" / "such.lock", FileLock::Wait::kNo); }),
             "cannot open the lock file to lock it");
}

TEST(FileLock, AnOutputDirectoryIsWrittenByOneCommandAtATime) {
  iotest::ScratchDir dir;
  const fs::path target = dir / "out";
  OutputDir a(target, {});
  EXPECT_HAS(error_of([&] { OutputDir b(target, {}); }), "another wheelins command is writing there right now");
  iotest::write_text(a.staging() / "trajectory.csv", "one\n");
  a.commit();
  OutputDirOptions force;
  force.overwrite = true;
  OutputDir c(target, force);  // the lock went with the commit
  c.commit();
}
