// The points file of `odemag field` and the argument parser of the commands.
#include <gtest/gtest.h>

#include "cli/cli.h"
#include "odemag/scene.h"

namespace odemag::cli {
namespace {

TEST(CliPoints, ReadsPointsSkippingHeaderCommentsAndBlankLines) {
  const auto p = parse_points("# probe line\n\n x , y , z \n0,0,0.1\r\n1e-3, -2 ,3.5 # tip\n\n", "p.csv");
  ASSERT_EQ(p.size(), 2u);
  EXPECT_EQ(p[0].z, 0.1);
  EXPECT_EQ(p[1].x, 1e-3);
  EXPECT_EQ(p[1].y, -2.0);
  EXPECT_EQ(p[1].z, 3.5);
}

TEST(CliPoints, EmptyFileHasNoPoints) { EXPECT_TRUE(parse_points("", "p.csv").empty()); }

// Returns the error for text that must be rejected.
SceneError points_rejection(const std::string& text) {
  try {
    parse_points(text, "p.csv");
  } catch (const SceneError& e) {
    return e;
  }
  ADD_FAILURE() << "accepted: " << text;
  return SceneError("", "", "");
}

TEST(CliPoints, MalformedLineNamesFileAndLine) {
  const SceneError e = points_rejection("x,y,z\n0,0,1\n\n1,2\n");
  EXPECT_EQ(e.file(), "p.csv");
  EXPECT_EQ(e.key(), "line 4");
  EXPECT_EQ(points_rejection("1,2,3,4\n").key(), "line 1");
  EXPECT_EQ(points_rejection("1,2,abc\n").key(), "line 1");
  EXPECT_EQ(points_rejection("0,0,0\n1,,3\n").key(), "line 2");
  EXPECT_EQ(points_rejection("1,2,1e999\n").key(), "line 1");
  EXPECT_EQ(points_rejection("1,2,nan\n").key(), "line 1");
  // A header is only allowed as the first line.
  EXPECT_EQ(points_rejection("0,0,0\nx,y,z\n").key(), "line 2");
}

TEST(CliArguments, OptionsAndPositionals) {
  const Arguments a = parse_arguments("field", {"s.json", "--points", "-", "--threads=2"},
                                      {"points", "threads", "backend"});
  ASSERT_EQ(a.positional.size(), 1u);
  EXPECT_EQ(a.positional[0], "s.json");
  EXPECT_EQ(*a.option("points"), "-");
  EXPECT_EQ(*a.option("threads"), "2");
  EXPECT_FALSE(a.option("backend").has_value());
  EXPECT_EQ(*solve_options(a).threads, 2);
}

TEST(CliArguments, RejectsBadOptions) {
  EXPECT_THROW(parse_arguments("solve", {"s.json", "--frob", "1"}, {"threads"}), UsageError);
  EXPECT_THROW(parse_arguments("solve", {"s.json", "-x"}, {"threads"}), UsageError);
  EXPECT_THROW(parse_arguments("solve", {"s.json", "--threads"}, {"threads"}), UsageError);
  EXPECT_THROW(parse_arguments("solve", {"--threads", "1", "--threads", "2"}, {"threads"}), UsageError);
  EXPECT_THROW(solve_options(parse_arguments("solve", {"--threads", "-1"}, {"threads"})), UsageError);
  EXPECT_THROW(solve_options(parse_arguments("solve", {"--threads", "2x"}, {"threads"})), UsageError);
  EXPECT_THROW(solve_options(parse_arguments("solve", {"--backend", "gpu"}, {"backend"})), UsageError);
}

}  // namespace
}  // namespace odemag::cli
