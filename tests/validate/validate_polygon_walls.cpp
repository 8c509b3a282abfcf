// Long validations of polygons against walls of any shape (`make validate`, label "validate"); the short versions are
// in tests/test_polygon_walls.cpp. A bed of polygons in a slowly turning drum that is a circle, and in a closed
// polyline of 256 segments inscribed in it (mitred joints all round, docs/physics.md G.6): in both the torque on the
// drum balances the bed's weight, and the bed is lifted to the same angle within the spread of the flow.
#include <gtest/gtest.h>

#include <cmath>

#include "../physics_util.hpp"
#include "../polygon_util.hpp"

namespace haet {
namespace {

using testing::record;

TEST(PolygonWallsLong, DrumOfSegmentsLiftsTheBedAsTheCircle) {
    const testing::DrumBed circle = testing::drumBed(0, 1.0, 2.0);
    const testing::DrumBed segments = testing::drumBed(256, 1.0, 2.0);
    record("circle_torque_over_weight_torque", circle.torque / circle.weightTorque - 1);
    record("segments_torque_over_weight_torque", segments.torque / segments.weightTorque - 1);
    record("circle_lift_angle_deg", circle.liftAngle);
    record("segments_lift_angle_deg", segments.liftAngle);
    EXPECT_NEAR(circle.torque, circle.weightTorque, 0.02 * std::abs(circle.weightTorque));
    EXPECT_NEAR(segments.torque, segments.weightTorque, 0.02 * std::abs(segments.weightTorque));
    EXPECT_GT(circle.liftAngle, 5.0);
    EXPECT_NEAR(segments.liftAngle, circle.liftAngle, 3.0);
}

}  // namespace
}  // namespace haet
