// ps11::fillLanes (ps11/fill_lanes.h): exactly lanes [0, n) take the value, bit for bit, for every
// run length across the vector steps, the overlapping last store and the short runs done lane by lane.
#include <catch2/catch.hpp>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <vector>

#include "ps11/fill_lanes.h"

TEST_CASE("fillLanes: lanes [0, n) take the value's bits, nothing past them is written", "[lanes]") {
    const float floats[] = {0.0f, -0.0f, 1.0f, 0.25f, -3.5f, std::numeric_limits<float>::quiet_NaN(),
                            std::numeric_limits<float>::infinity(), 1e-40f};
    const int16_t words[] = {0, 1, -1, 255, 4080, -32768, 32767};
    for (int n = 0; n <= 40; ++n) {
        for (float value : floats) {
            std::vector<float> lanes(48, 7.0f);
            ps11::fillLanes(lanes.data() + 1, n, value);
            CHECK(lanes[0] == 7.0f);
            for (int i = 0; i < n; ++i) CHECK(std::memcmp(&lanes[size_t(i) + 1], &value, sizeof value) == 0);
            for (size_t i = size_t(n) + 1; i < lanes.size(); ++i) CHECK(lanes[i] == 7.0f);
        }
        for (int16_t value : words) {
            std::vector<int16_t> lanes(48, 7);
            ps11::fillLanes(lanes.data() + 1, n, value);
            CHECK(lanes[0] == 7);
            for (int i = 0; i < n; ++i) CHECK(lanes[size_t(i) + 1] == value);
            for (size_t i = size_t(n) + 1; i < lanes.size(); ++i) CHECK(lanes[i] == 7);
        }
    }
}
