#include "core/contact_point.h"

#include <string>

#include <gtest/gtest.h>

#include "core/error.h"
#include "tests/support/error_text.h"

namespace ss {
namespace {

TEST(ContactPointOptions, DefaultsAreValid) {
  std::string why = "stale";
  EXPECT_TRUE(ContactPointOptions{}.IsValid(&why)) << why;
  EXPECT_EQ(why, "");
}

TEST(ContactPointOptions, NamesTheFieldOutOfRange) {
  ContactPointOptions o;
  o.band_fraction = 1.5;
  std::string why;
  EXPECT_FALSE(o.IsValid(&why));
  EXPECT_EQ(why.rfind("band_fraction: ", 0), 0u) << why;
  o = {};
  o.min_band_px = 0;  // the band would divide by 0
  EXPECT_FALSE(o.IsValid(&why));
  EXPECT_EQ(why.rfind("min_band_px: ", 0), 0u) << why;
  o.band_fraction = -0.1;
  EXPECT_FALSE(o.IsValid(&why));
  EXPECT_NE(why.find("band_fraction: "), std::string::npos) << why;
  EXPECT_NE(why.find("\nmin_band_px: "), std::string::npos) << why;
}

TEST(ContactPoint, RefusesOptionsOutOfRange) {
  cv::Mat alpha(20, 10, CV_8U, cv::Scalar(255));
  cv::Point2d p;
  EXPECT_TRUE(ContactPoint(alpha, &p));
  ContactPointOptions o;
  o.min_band_px = -1;
  const std::string what = testing::InputErrorOf([&] { ContactPoint(alpha, &p, o); });
  EXPECT_EQ(what.rfind("contact point options: min_band_px: ", 0), 0u) << what;
}

}  // namespace
}  // namespace ss
