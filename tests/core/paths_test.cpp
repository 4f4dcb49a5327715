#include "core/paths.hpp"

#include <gtest/gtest.h>

namespace iesrgs {
namespace {

TEST(Paths, ExtensionsCompareInAnyCase) {
  EXPECT_EQ(lowercase_extension("scene/OUT.SPLAT"), ".splat");
  EXPECT_EQ(lowercase_extension("model.Ply"), ".ply");
  EXPECT_EQ(lowercase_extension("no_extension"), "");
  EXPECT_TRUE(is_image_file("r_0.PNG"));
  EXPECT_TRUE(is_image_file("DSC_0001.JPG"));
  EXPECT_TRUE(is_image_file("a.jpeg"));
  EXPECT_FALSE(is_image_file("depth.npy"));
  EXPECT_FALSE(is_image_file("notes.txt"));
}

TEST(Paths, ShellWordsQuoteOnlyWhatAShellWouldSplitOrExpand) {
  EXPECT_EQ(shell_word("/data/lego-x4/run_1.5,b=c"), "/data/lego-x4/run_1.5,b=c");
  EXPECT_EQ(shell_word("my scenes/lego"), "'my scenes/lego'");
  EXPECT_EQ(shell_word("$HOME/*"), "'$HOME/*'");
  EXPECT_EQ(shell_word("it's"), "'it'\\''s'");
  EXPECT_EQ(shell_word(""), "''");
}

}  // namespace
}  // namespace iesrgs
