#include "pipeline/rows.hpp"

#include <gtest/gtest.h>

#include "core/error.hpp"

namespace iesrgs::pipeline {
namespace {

using Rows = std::vector<std::string>;

TEST(Rows, GroupsExpandInTableOrder) {
  EXPECT_EQ(expand_rows({"demo"}), (Rows{"bicubic", "internal", "external", "ie-srgs"}));
  EXPECT_EQ(expand_rows({"ablation"}),
            (Rows{"internal", "external", "external-depth", "joint", "joint-depth", "ie-srgs"}));
  EXPECT_EQ(expand_rows({"hr", "bicubic", "demo"}),
            (Rows{"bicubic", "internal", "external", "ie-srgs", "hr"}));
  EXPECT_EQ(expand_rows({"all"}).size(), 9u);
}

TEST(Rows, UnknownNamesAreRefusedWithTheList) {
  try {
    expand_rows({"external", "ie_srgs"});
    FAIL() << "an unknown row was accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("unknown row 'ie_srgs'"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("mask-oracle (IE-SRGS with the oracle mask"),
              std::string::npos)
        << e.what();
  }
  EXPECT_THROW(expand_rows({}), Error);
}

TEST(Rows, SpecsSayWhatSupervisesEachRow) {
  EXPECT_EQ(row_spec("ie-srgs").texture, loss::TextureGuidance::Masked);
  EXPECT_TRUE(row_spec("ie-srgs").internal_depth && row_spec("ie-srgs").external_depth);
  EXPECT_EQ(row_spec("joint").texture, loss::TextureGuidance::Average);
  EXPECT_EQ(row_spec("bicubic").source, Source::Bicubic);
  EXPECT_TRUE(RowSpec::needs_truth(row_spec("hr")));
  EXPECT_TRUE(RowSpec::needs_truth(row_spec("mask-oracle")));
  EXPECT_FALSE(RowSpec::needs_truth(row_spec("ie-srgs")));
  EXPECT_EQ(find_row("nope"), nullptr);
  EXPECT_LT(table_position("external"), table_position("ie-srgs"));
}

}  // namespace
}  // namespace iesrgs::pipeline
