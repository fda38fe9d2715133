// The query of the browser viewer's profile requests (/profile.png, .las, .csv): the exact shapes accepted,
// anything else refused with one sentence; and a generated scene refused before anything is cut.
#include <string>

#include <gtest/gtest.h>

#include "base/error.h"
#include "view/web/export.h"

namespace pointrast::view::web {
namespace {

std::string refused(const std::string& query, ProfileOutput output = ProfileOutput::Png) {
  try {
    parseProfileQuery(query, output);
  } catch (const InputError& e) {
    return e.what();
  }
  ADD_FAILURE() << query << " was accepted";
  return "";
}

TEST(ProfileQuery, ALineAWidthAndForThePictureASize) {
  const ProfileQuery q =
      parseProfileQuery("line=636400.5%2C849100,636900,849350,637000,849400&width=16&size=600x300&token=abc",
                        ProfileOutput::Png);
  ASSERT_EQ(q.line.vertices.size(), 3u);
  EXPECT_EQ(q.line.vertices[0], glm::dvec2(636400.5, 849100));
  EXPECT_EQ(q.line.vertices[2], glm::dvec2(637000, 849400));
  EXPECT_EQ(q.line.width, 16);
  EXPECT_EQ(q.width, 600u);
  EXPECT_EQ(q.height, 300u);
  const ProfileQuery las = parseProfileQuery("width=0.25&line=1,2,3,4", ProfileOutput::Las);
  EXPECT_EQ(las.line.vertices.size(), 2u);
  EXPECT_EQ(las.line.width, 0.25);
  EXPECT_EQ(las.width, 0u);
  EXPECT_EQ(parseProfileQuery("line=1,2,3,4&width=1", ProfileOutput::Csv).line.vertices.size(), 2u);
  EXPECT_EQ(parseProfileQuery("line=1,2,3,4&width=1&size=4096x120", ProfileOutput::Png).width, 4096u);
}

TEST(ProfileQuery, BadValuesAreRefusedWithOneSentence) {
  const std::string line = "line=0,0,10,0";
  EXPECT_NE(refused("width=1&size=600x300").find("line is missing"), std::string::npos);
  EXPECT_NE(refused(line + "&size=600x300").find("width is missing"), std::string::npos);
  EXPECT_NE(refused(line + "&width=1").find("size is missing"), std::string::npos);
  EXPECT_NE(refused("line=1,2&width=1&size=600x300").find("two or more"), std::string::npos);
  EXPECT_NE(refused("line=1,2,3&width=1&size=600x300").find("two or more"), std::string::npos);
  EXPECT_NE(refused("line=1,2,3,nan&width=1&size=600x300").find("two or more"), std::string::npos);
  EXPECT_NE(refused("line=1,2,,4&width=1&size=600x300").find("two or more"), std::string::npos);
  EXPECT_NE(refused("line=5,5,5,5&width=1&size=600x300").find("no length"), std::string::npos);
  EXPECT_NE(refused(line + "&width=0&size=600x300").find("positive"), std::string::npos);
  EXPECT_NE(refused(line + "&width=-3&size=600x300").find("positive"), std::string::npos);
  EXPECT_NE(refused(line + "&width=inf&size=600x300").find("finite"), std::string::npos);
  EXPECT_NE(refused(line + "&width=1&width=2&size=600x300").find("twice"), std::string::npos);
  EXPECT_NE(refused(line + "&" + line + "&width=1&size=600x300").find("twice"), std::string::npos);
  for (const char* size : {"199x300", "600x119", "4097x300", "600x4097", "600", "x300", "600x", "-600x300",
                           "600x300x2", "0x0", "99999999999x300", "600 x300"})
    EXPECT_NE(refused(line + "&width=1&size=" + size).find("size takes WxH"), std::string::npos) << size;
  EXPECT_NE(refused(line + "&width=1&size=600x300&classes=2").find("unknown parameter"), std::string::npos);
  // A picture's size means nothing to the downloads.
  EXPECT_NE(refused(line + "&width=1&size=600x300", ProfileOutput::Las).find("unknown parameter"),
            std::string::npos);
  EXPECT_NE(refused(line + "&width=1%ZZ").find("%-escape"), std::string::npos);
}

TEST(ProfileQuery, TooManyVerticesAreRefused) {
  std::string line = "line=";
  for (size_t i = 0; i <= kMaxProfileVertices; ++i)
    line += std::to_string(i) + ",0,";
  line.pop_back();
  EXPECT_NE(refused(line + "&width=1&size=600x300").find("more than"), std::string::npos);
}

TEST(ProfileQuery, AGeneratedSceneHasNoFileToCut) {
  const ProfileQuery q = parseProfileQuery("line=0,0,1,1&width=1", ProfileOutput::Las);
  bool sent = false;
  try {
    exportProfile("", q, ProfileOutput::Las, [&](const std::filesystem::path&, uint64_t) { sent = true; });
    ADD_FAILURE() << "a generated scene was cut";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("generated scene"), std::string::npos) << e.what();
  }
  EXPECT_FALSE(sent);
}

} // namespace
} // namespace pointrast::view::web
