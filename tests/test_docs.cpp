// The documentation kept in step: scripts/check-docs.sh (the README's quick start, the docs
// index listing every document, every relative link resolving, no copied option lists).
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
