#include <gtest/gtest.h>
#include "animat/config.hpp"
TEST(Build, DefaultConfigValidates) { EXPECT_NO_THROW(animat::validate(animat::Config{})); }
