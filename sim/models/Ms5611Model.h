// SPDX-License-Identifier: GPL-3.0-or-later
// MS5611-01BA03 barometer on SPI (Measurement Specialties MS5611-01BA03 datasheet; AN520
// "C-code example for MS56xx, MS57xx (except analog sensor), and MS58xx series pressure
// sensors" for the PROM CRC), driven by the true height.
//
// Host-only, no simavr: the harness calls set_chip_select() with the level of pin 40
// (PG1) and transfer() for each SPI byte while it is low.
//
// What is modelled:
// - SPI framing: chip select low starts a command; the first byte is the command, the
//   following bytes clock out its answer MSB first (0x00 on MISO otherwise, and while
//   the chip select is high the chip does not drive MISO at all: the harness's 0x00).
// - Commands: RESET 0x1E (PROM reloaded, the chip deaf for kReset_s: commands then are
//   ignored and counted); CONVERT D1 0x40/42/44/46/48 and D2 0x50/52/54/56/58 (OSR 256,
//   512, 1024, 2048, 4096), done after the datasheet's maximum conversion time 0.60, 1.17,
//   2.28, 4.54, 9.04 ms; ADC READ 0x00 then 3 bytes, the 24-bit result, which reads 0 when
//   no conversion finished since the last read (a read during a conversion returns 0 and,
//   as the datasheet warns, spoils that conversion: its result reads 0 too); PROM READ
//   0xA0..0xAE then 2 bytes, word 0..7. A command during a conversion restarts it (the
//   datasheet: the result is then wrong; counted). Anything else is counted and ignored.
// - PROM: word 0 the factory word kProm[0], words 1..6 the coefficients C1..C6 of the
//   datasheet's worked example, word 7 a serial code with the CRC-4 of AN520 in its low
//   4 bits.
// - D1 and D2: from the pressure and temperature at the middle of the conversion, by
//   inverting the datasheet's compensation ("Pressure and temperature calculation", first
//   order, and the second order below 20 degC): D2 is the smallest code whose compensated
//   TEMP reaches the temperature, D1 the code whose compensated P is nearest the pressure
//   (both searched over the 24-bit range with the datasheet's own integer arithmetic), so
//   that a driver doing the datasheet's arithmetic gets back the pressure within 0.02 Pa.
//   Pressure: the International Standard Atmosphere at the height above mean sea level
//   (home altitude - d), plus white noise of noise_pa (default 10 Pa = 0.1 hPa, ~0.85 m;
//   seeded) per conversion. Temperature: fixed_temperature_c when set, else the standard
//   atmosphere's at that height.
// - SPI mode: the chip takes mode 0 and mode 3 (CPHA = CPOL); bytes in mode 1 or 2 are
//   counted (their bits would be shifted on the chip; here they are read as sent).
#pragma once

#include <stdint.h>

#include "Geodesy.h"
#include "Noise.h"
#include "TimeWindow.h"
#include "Trajectory.h"

namespace sim {

struct Ms5611Options {
    GeodeticPoint home{kHomeLat_deg, kHomeLon_deg, kHomeAlt_m};
    double noise_pa = 10.0;            // 1-sigma per conversion
    bool fixed_temperature = false;    // else the standard atmosphere's at the height
    double temperature_c = 25.0;
    uint64_t seed = 1;
};

struct Ms5611Faults {
    TimeWindows absent;  // MISO not driven (0x00), commands ignored
    TimeWindows stuck;   // conversions return the last result from before the window
    TimeWindows spike;   // D1 read with bit 19 flipped (~100 hPa, ~900 m off)
};

struct Ms5611Counters {
    uint32_t transactions = 0;           // chip-select low periods with at least one byte
    uint32_t bytes = 0;
    uint32_t resets = 0;
    uint32_t conversions = 0;            // started
    uint32_t prom_reads = 0;
    uint32_t adc_reads = 0;
    uint32_t adc_reads_zero = 0;         // no result ready: before the end, twice, or none
    uint32_t reads_during_conversion = 0;
    uint32_t commands_during_conversion = 0;
    uint32_t commands_during_reset = 0;
    uint32_t unknown_commands = 0;
    uint32_t bytes_while_absent = 0;
    uint32_t bytes_wrong_spi_mode = 0;   // SPI mode 1 or 2
};

class Ms5611Model {
public:
    static constexpr double kReset_s = 0.0028;  // datasheet: reload after reset, 2.8 ms
    // The datasheet's maximum conversion times, OSR 256, 512, 1024, 2048, 4096.
    static constexpr double kConversion_s[5] = {0.60e-3, 1.17e-3, 2.28e-3, 4.54e-3, 9.04e-3};
    static const uint16_t kProm[8];  // word 7's low 4 bits: the CRC

    Ms5611Model(const Trajectory& trajectory, const Ms5611Options& options);  // copies
    Trajectory& trajectory() { return trajectory_; }

    void advance_to(double t_s);
    double time_s() const { return time_s_; }

    void set_chip_select(bool selected);
    // One SPI byte while selected; spi_mode 0..3 (CPOL << 1 | CPHA).
    uint8_t transfer(uint8_t mosi, int spi_mode = 0);

    // The codes the chip reports for a pressure and temperature (noise-free): the
    // inverse of lib/MS5611's compensation (Ms5611Math.h), which the firmware runs.
    static void codes_for(const uint16_t prom[8], double pressure_pa, double temperature_c, uint32_t& d1, uint32_t& d2);

    // The truth now: pressure (Pa) and temperature (degC) at the board's height.
    double pressure_pa_at(double t_s);
    double temperature_c_at(double t_s);

    Ms5611Faults& faults() { return faults_; }
    const Ms5611Counters& counters() const { return counters_; }

private:
    void finish_conversion();
    void command(uint8_t cmd);

    Trajectory trajectory_;
    Ms5611Options options_;
    Ms5611Faults faults_;
    Ms5611Counters counters_;
    NoiseSource noise_;

    double time_s_ = 0.0;
    double reset_until_s_ = -1.0;
    // The conversion in progress.
    bool converting_ = false;
    bool converting_d1_ = false;
    bool conversion_spoiled_ = false;
    double conversion_start_s_ = 0.0, conversion_end_s_ = 0.0;
    // The ADC result register.
    bool result_ready_ = false;
    uint32_t result_ = 0;
    uint32_t last_d1_ = 0, last_d2_ = 0;  // for `stuck`
    bool have_last_d1_ = false, have_last_d2_ = false;

    bool selected_ = false;
    int byte_index_ = 0;
    uint8_t answer_[3] = {0, 0, 0};
    int answer_length_ = 0;
};

}  // namespace sim
