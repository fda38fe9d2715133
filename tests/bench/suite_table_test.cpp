// The suite table (bench/suites.cpp): every suite is one row, and everything that names suites reads it.
#include <string>

#include <gtest/gtest.h>

#include "base/error.h"
#include "bench/suites.h"

namespace pointrast::bench {
namespace {

TEST(SuiteTable, EveryRowIsFoundByNameAndHasDataSets) {
  ASSERT_EQ(suites().size(), suiteNames().size());
  for (const Suite& suite : suites()) {
    SCOPED_TRACE(suite.name);
    EXPECT_EQ(findSuite(suite.name), &suite);
    if (suite.kind == SuiteKind::Spheres) {
      EXPECT_FALSE(suite.spheres.empty());
      EXPECT_EQ(sphereSuiteDatasets(suite.name, 0.001, 1).size(), suite.spheres.size());
      EXPECT_THROW(suiteDatasets(suite.name, 0.001, 1), InputError) << "no point data sets";
    } else {
      EXPECT_FALSE(suite.points.empty());
      EXPECT_EQ(suiteDatasets(suite.name, 0.001, 1).size(), suite.points.size());
      EXPECT_THROW(sphereSuiteDatasets(suite.name, 0.001, 1), InputError) << "no particle data sets";
    }
    EXPECT_EQ(isSphereSuite(suite.name), suite.kind == SuiteKind::Spheres);
    EXPECT_EQ(isLodSuite(suite.name), suite.kind == SuiteKind::Lod);
    EXPECT_EQ(isVrSuite(suite.name), suite.kind == SuiteKind::Vr);
    suiteDefaults(suite.name); // does not throw
  }
  EXPECT_EQ(findSuite("paper1999"), nullptr);
}

TEST(SuiteTable, AnUnknownNameListsEverySuite) {
  try {
    suiteDefaults("paper1999");
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_STREQ(e.what(),
                 "unknown suite 'paper1999'; choose paper2021, paper2022, lod, vr2022 or spheres2023");
  }
}

} // namespace
} // namespace pointrast::bench
