#include <gtest/gtest.h>
TEST(VpDetectRun, Placeholder) {}
