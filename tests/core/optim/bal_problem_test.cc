#include "core/optim/bal_problem.h"

#include <gtest/gtest.h>

#include <string>

namespace reconar {
namespace {

const char kGood[] =
    "2 2 3\n"
    "0 0 1.5 -2.5\n"
    "1 0 3 4\n"
    "1 1 -1e2 5\n"
    "0.1\n0.2\n0.3\n1\n2\n3\n500\n0.01\n0.001\n"
    "0\n0\n0\n0\n0\n-5\n400\n0\n0\n"
    "1\n2\n3\n"
    "4 5 6\n";

TEST(BalProblemTest, ParsesWellFormedText) {
  Result<BalProblem> r = ParseBalProblem(kGood, "mem.txt");
  ASSERT_TRUE(r.ok()) << r.status().ToString();
  const BalProblem& p = *r;
  EXPECT_EQ(p.num_cameras(), 2);
  EXPECT_EQ(p.num_points(), 2);
  ASSERT_EQ(p.observations.size(), 3u);
  EXPECT_EQ(p.observations[2].camera, 1);
  EXPECT_EQ(p.observations[2].point, 1);
  EXPECT_DOUBLE_EQ(p.observations[2].x, -100.0);
  EXPECT_DOUBLE_EQ(p.camera(0)[6], 500.0);
  EXPECT_DOUBLE_EQ(p.camera(1)[5], -5.0);
  EXPECT_DOUBLE_EQ(p.point(1)[2], 6.0);
  EXPECT_TRUE(p.Check().ok());
}

TEST(BalProblemTest, TruncatedFileNamesFileAndLine) {
  std::string text(kGood);
  text.resize(text.size() - 4);  // drop "6\n" and more
  text = text.substr(0, text.find("4 5"));
  Result<BalProblem> r = ParseBalProblem(text, "cut.txt");
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.status().code(), StatusCode::kCorruptData);
  EXPECT_NE(r.status().message().find("cut.txt:"), std::string::npos) << r.status().message();
  EXPECT_NE(r.status().message().find("end of file"), std::string::npos) << r.status().message();
}

TEST(BalProblemTest, NonNumericTokenNamesLine) {
  std::string text(kGood);
  text.replace(text.find("3 4"), 3, "3 x4");
  Result<BalProblem> r = ParseBalProblem(text, "bad.txt");
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.status().message().find("bad.txt:3:"), std::string::npos) << r.status().message();
  EXPECT_NE(r.status().message().find("'x4'"), std::string::npos) << r.status().message();
}

TEST(BalProblemTest, BadCountsAndIndicesRejected) {
  for (const char* text : {"-1 2 3\n", "2 2\n", "1 1 1000000000\n0 0 1 1\n", "a 1 1\n",
                           "2 2 1\n5 0 1 1\n", "0 0 1\n"}) {
    Result<BalProblem> r = ParseBalProblem(text, "c.txt");
    ASSERT_FALSE(r.ok()) << text;
    EXPECT_EQ(r.status().code(), StatusCode::kCorruptData) << text;
    EXPECT_EQ(r.status().message().rfind("c.txt:", 0), 0u) << r.status().message();
  }
  std::string text = "2 2 1\n0 7 1 1\n";
  for (int k = 0; k < 24; ++k) text += "0\n";
  Result<BalProblem> r = ParseBalProblem(text, "c.txt");
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.status().message().find("c.txt:2:"), std::string::npos) << r.status().message();
}

TEST(BalProblemTest, MissingFileIsNotFound) {
  Result<BalProblem> r = ReadBalProblem("/nonexistent/problem.txt");
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.status().code(), StatusCode::kNotFound);
  EXPECT_NE(r.status().message().find("/nonexistent/problem.txt"), std::string::npos);
}

}  // namespace
}  // namespace reconar
