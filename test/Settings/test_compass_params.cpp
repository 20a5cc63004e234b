// SPDX-License-Identifier: GPL-3.0-or-later
// The compass calibration as ArduPilot's parameters (lib/Settings/Params): COMPASS_OFS_*
// in milligauss with ArduPilot's sign, COMPASS_DIA_* and COMPASS_ODI_* as the soft-iron
// matrix, all rows into Settings::cal: the first record's calibration bytes, never its
// flight bytes or the second record's.
#include <gtest/gtest.h>

#include <cmath>
#include <cstddef>
#include <cstring>
#include <string>
#include <vector>

#include "Params.h"
#include "SensorCalibration.h"
#include "Settings.h"

namespace {

uint16_t index_of(const char* name) {
    const int16_t i = params::find(name);
    EXPECT_GE(i, 0) << name;
    return (uint16_t)i;
}

TEST(CompassParams, NamesXYZInEitherCase) {
    const uint16_t x = index_of("COMPASS_OFS_X");
    EXPECT_EQ(index_of("COMPASS_OFS_Y"), x + 1);
    EXPECT_EQ(index_of("compass_ofs_z"), x + 2);
    EXPECT_EQ(params::find("COMPASS_OFS_W"), -1);
    EXPECT_EQ(params::find("COMPASS_OFS_"), -1);
    EXPECT_EQ(params::find("COMPASS_OFS_XX"), -1);
    params::Info in;
    ASSERT_TRUE(params::info(index_of("COMPASS_ODI_Z"), in));
    EXPECT_STREQ(in.name, "COMPASS_ODI_Z");
    EXPECT_EQ(in.type, params::Type::Float);
    ASSERT_TRUE(params::info(x, in));
    EXPECT_EQ(in.type, params::Type::MagOfs);
    EXPECT_FALSE(params::is_integer(in.type));
    // The digits' rows are still found by their number only.
    EXPECT_EQ(params::find("RC1_MIN") + 7, params::find("RC8_MIN"));
    EXPECT_EQ(params::find("RCX_MIN"), -1);
}

// ArduPilot adds COMPASS_OFS to the field (AP_Compass); `cal mag`'s offset is subtracted
// (calib::apply_mag): the parameter is the offset with its sign turned, in milligauss.
TEST(CompassParams, OffsetsAreArduPilotsMilligaussWithItsSign) {
    settings::Settings s = settings::defaults();
    s.cal.mag_offset_uT = linalg::Vector3f(8.01f, -5.02f, 3.0f);
    EXPECT_FLOAT_EQ(params::get(s, index_of("COMPASS_OFS_X")), -80.1f);
    EXPECT_FLOAT_EQ(params::get(s, index_of("COMPASS_OFS_Y")), 50.2f);
    EXPECT_FLOAT_EQ(params::get(s, index_of("COMPASS_OFS_Z")), -30.0f);
    ASSERT_TRUE(params::set(s, index_of("COMPASS_OFS_Y"), 123.4f));
    EXPECT_FLOAT_EQ(s.cal.mag_offset_uT.y, -12.34f);
    // A value sent comes back as sent (a ground station compares): every 0.01 mGauss step.
    for (float v = -2000.0f; v <= 2000.0f; v += 37.13f) {
        const float sent = std::round(v * 100.0f) / 100.0f;
        ASSERT_TRUE(params::set(s, index_of("COMPASS_OFS_X"), sent));
        EXPECT_EQ(params::get(s, index_of("COMPASS_OFS_X")), sent) << sent;
    }
    // Beyond what calib::is_plausible keeps (200 uT): refused, nothing changed.
    EXPECT_FALSE(params::set(s, index_of("COMPASS_OFS_Z"), 2000.5f));
    EXPECT_FALSE(params::set(s, index_of("COMPASS_OFS_Z"), std::nanf("")));
    EXPECT_FLOAT_EQ(s.cal.mag_offset_uT.z, 3.0f);
    EXPECT_TRUE(params::set(s, index_of("COMPASS_OFS_Z"), -2000.0f));
    EXPECT_TRUE(calib::is_plausible(s.cal));
    EXPECT_TRUE(settings::is_valid(s));
    EXPECT_FLOAT_EQ(params::compass_ofs_mgauss(-12.345678f), 123.46f);
}

TEST(CompassParams, SoftIronIsTheSymmetricMatrix) {
    settings::Settings s = settings::defaults();
    EXPECT_FLOAT_EQ(params::get(s, index_of("COMPASS_DIA_X")), 1.0f);
    EXPECT_FLOAT_EQ(params::get(s, index_of("COMPASS_ODI_Y")), 0.0f);
    ASSERT_TRUE(params::set(s, index_of("COMPASS_DIA_Z"), 1.03f));
    ASSERT_TRUE(params::set(s, index_of("COMPASS_ODI_X"), 0.02f));  // xy
    ASSERT_TRUE(params::set(s, index_of("COMPASS_ODI_Z"), -0.01f));  // yz
    EXPECT_FLOAT_EQ(s.cal.mag_scale.z, 1.03f);
    EXPECT_FLOAT_EQ(s.cal.mag_cross.x, 0.02f);
    EXPECT_FLOAT_EQ(s.cal.mag_cross.z, -0.01f);
    EXPECT_FALSE(params::set(s, index_of("COMPASS_DIA_X"), 0.4f));
    EXPECT_FALSE(params::set(s, index_of("COMPASS_ODI_Y"), 0.6f));
    // ArduPilot's correction M (m + ofs) is this firmware's W (m - offset).
    ASSERT_TRUE(params::set(s, index_of("COMPASS_OFS_X"), -80.0f));
    const linalg::Vector3f m(50.0f, 10.0f, -20.0f);
    const linalg::Vector3f f = calib::apply_mag(s.cal, m);
    const float ax = m.x - 8.0f;  // m + ofs, in uT
    EXPECT_NEAR(f.x, 1.0f * ax + 0.02f * m.y + 0.0f * m.z, 1e-4f);
    EXPECT_NEAR(f.y, 0.02f * ax + 1.0f * m.y - 0.01f * m.z, 1e-4f);
    EXPECT_NEAR(f.z, 0.0f * ax - 0.01f * m.y + 1.03f * m.z, 1e-4f);
}

TEST(CompassParams, OnlyTheseNineAreTheCompassCalibration) {
    uint16_t n = 0;
    params::Info in;
    for (uint16_t i = 0; i < params::count(); ++i) {
        if (!params::is_compass_calibration(i)) continue;
        ++n;
        ASSERT_TRUE(params::info(i, in));
        EXPECT_EQ(std::strncmp(in.name, "COMPASS_", 8), 0) << in.name;
    }
    EXPECT_EQ(n, 9u);
    EXPECT_FALSE(params::is_compass_calibration(index_of("COMPASS_DEC")));
    EXPECT_FALSE(params::is_compass_calibration(params::count()));
}

// The rows point into Settings::cal: setting them changes the first record's calibration
// bytes (kept over a power cycle with it) and neither its flight bytes nor the second record.
TEST(CompassParams, RowsLiveInTheFirstRecordsCalibration) {
    settings::Settings in = settings::defaults();
    uint8_t flight_def[settings::kFlightBytes], flight_in[settings::kFlightBytes];
    params::encode_flight(in, flight_def);
    uint8_t vehicle_def[240], vehicle_in[240];
    const uint8_t nv = (uint8_t)params::vehicle_bytes();
    params::vehicle_part(in, 0, nv, vehicle_def);
    ASSERT_TRUE(params::set(in, index_of("COMPASS_OFS_X"), -80.0f));
    ASSERT_TRUE(params::set(in, index_of("COMPASS_DIA_Y"), 1.05f));
    ASSERT_TRUE(params::set(in, index_of("COMPASS_ODI_Z"), 0.03f));
    params::encode_flight(in, flight_in);
    params::vehicle_part(in, 0, nv, vehicle_in);
    EXPECT_EQ(0, std::memcmp(flight_in, flight_def, sizeof flight_in));
    EXPECT_EQ(0, std::memcmp(vehicle_in, vehicle_def, nv));
    uint8_t record[settings::kRecordSize];
    settings::encode(in, record);
    settings::Settings out;
    ASSERT_EQ(settings::decode(record, out), settings::LoadResult::Ok);
    EXPECT_FLOAT_EQ(params::get(out, index_of("COMPASS_OFS_X")), -80.0f);
    EXPECT_FLOAT_EQ(out.cal.mag_scale.y, 1.05f);
    EXPECT_FLOAT_EQ(out.cal.mag_cross.z, 0.03f);
}

}  // namespace

namespace {

// What each calibration announces when it ends (params::rows_within): exactly the rows it
// wrote, by name, in table order.
TEST(CalibrationRows, EachCalibrationsRowsByName) {
    using settings::Settings;
    struct Case {
        uint16_t from, to;
        std::vector<std::string> names;
    };
    const Case cases[] = {
        {offsetof(Settings, cal.mag_offset_uT), offsetof(Settings, cal.mag_learned_uT),
         {"COMPASS_OFS_X", "COMPASS_OFS_Y", "COMPASS_OFS_Z", "COMPASS_DIA_X", "COMPASS_DIA_Y", "COMPASS_DIA_Z",
          "COMPASS_ODI_X", "COMPASS_ODI_Y", "COMPASS_ODI_Z"}},
        {offsetof(Settings, vehicle.ahrs_trim_x_rad), offsetof(Settings, vehicle.ins_accoffs_m_s2),
         {"AHRS_TRIM_X", "AHRS_TRIM_Y"}},
        {offsetof(Settings, vehicle.ins_accoffs_m_s2), offsetof(Settings, vehicle.ins_accscal) + 12,
         {"INS_ACCOFFS_X", "INS_ACCOFFS_Y", "INS_ACCOFFS_Z", "INS_ACCSCAL_X", "INS_ACCSCAL_Y", "INS_ACCSCAL_Z"}},
        {offsetof(Settings, gnd_abs_press_pa), offsetof(Settings, gnd_abs_press_pa) + 4, {"GND_ABS_PRESS"}},
    };
    for (const Case& c : cases) {
        const params::Rows rows = params::rows_within(c.from, c.to);
        ASSERT_EQ(rows.count, c.names.size()) << c.names[0];
        for (uint8_t i = 0; i < rows.count; ++i) {
            params::Info in;
            ASSERT_TRUE(params::info((uint16_t)(rows.first + i), in));
            EXPECT_EQ(std::string(in.name), c.names[i]);
        }
        EXPECT_FALSE(rows.holds((uint16_t)(rows.first - 1u)));
        EXPECT_FALSE(rows.holds((uint16_t)(rows.first + rows.count)));
    }
    // Bytes no parameter lives in: none.
    EXPECT_EQ(params::rows_within(sizeof(Settings), sizeof(Settings) + 4).count, 0u);
}

}  // namespace
