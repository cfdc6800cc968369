// The documentation kept in step: scripts/check-docs.sh (the README's quick start, the docs
// index listing every document, every relative link resolving, no copied option lists), and
// the code's shape: scripts/check-function-length.py.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <cstdlib>
#include <string>

TEST(Docs, ReadmeAndIndexAreInStep) {
  const std::string cmd = std::string("'") + WHEELINS_SOURCE_DIR + "/scripts/check-docs.sh' '" + WHEELINS_SOURCE_DIR + "'";
  const int status = std::system(cmd.c_str());
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 0) << "scripts/check-docs.sh found the problems printed above";
}

// No function, lambda or class body over 80 lines in run/, study/, python/ and app/ (the run
// session's ring): scripts/check-function-length.py names any that grows past it.
TEST(CodeShape, NoBlockOverEightyLinesInTheRunSessionsRing) {
  const std::string cmd = std::string("python3 '") + WHEELINS_SOURCE_DIR + "/scripts/check-function-length.py' '" +
                          WHEELINS_SOURCE_DIR + "'";
  const int status = std::system(cmd.c_str());
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 0) << "scripts/check-function-length.py found the blocks printed above";
}
