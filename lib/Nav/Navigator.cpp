// SPDX-License-Identifier: GPL-3.0-or-later
#include "Navigator.h"

namespace nav {

namespace {

int32_t centimetres(float m) { return round_to_int32(m * 100.0f); }

}  // namespace

bool Navigator::on_fix(const gps::Fix& fix, const BaroReading& baro, uint8_t min_sats) {
    if (fix.fix != gps::FixType::k3D) return false;  // a 2D or no fix: the position moves on from the last
    float vel[3];
    for (uint8_t i = 0; i < 3; ++i) vel[i] = (float)fix.vel_ned_cm_s[i] * 0.01f;
    if (!fix.have_vertical_velocity) vel[2] = 0.0f;
    // A glitch before any good fix has nothing to be dead-reckoned from.
    const bool good = !fix.glitching || !have_position_;
    if (good) {
        base_.lat_e7 = fix.lat_e7;
        base_.lon_e7 = fix.lon_e7;
        base_.alt_cm = fix.alt_msl_mm / 10;
        if (!map_.valid()) map_.set_origin(base_);
    } else {
        // Dead reckoning over the rejected fix: the mean of the two fixes' velocities.
        const float half_dt_s = 0.5f * (float)(fix.received_ms - base_ms_) * 0.001f;
        base_ = map_.moved(base_, (vel_ned_m_s_[0] + vel[0]) * half_dt_s, (vel_ned_m_s_[1] + vel[1]) * half_dt_s);
        base_.alt_cm -= centimetres((vel_ned_m_s_[2] + vel[2]) * half_dt_s);
        if (glitched_fixes_ != UINT16_MAX) ++glitched_fixes_;
    }
    base_ms_ = fix.received_ms;
    for (uint8_t i = 0; i < 3; ++i) vel_ned_m_s_[i] = vel[i];
    have_position_ = true;

    bool home_now = false;
    if (good && !home_set() && fix.sats >= min_sats && fix.hdop_cm <= kMaxHdopCm) {
        take_home(base_, baro, HomeSource::kGps);
        home_now = true;
    }
    // The barometer's datum from the GPS when home could not give it (no barometer then).
    if (good && baro.healthy && !have_datum_) {
        baro_datum_cm_ = base_.alt_cm - centimetres(baro.height_m);
        have_datum_ = true;
    }
    update(fix.received_ms, baro);
    return home_now;
}

void Navigator::update(uint32_t now_ms, const BaroReading& baro) {
    if (!have_position_) return;
    now_ms_ = now_ms;
    uint32_t age_ms = now_ms - base_ms_;
    if (age_ms > kMaxExtrapolation_ms) age_ms = kMaxExtrapolation_ms;
    const float t_s = kGpsLag_s + (float)age_ms * 0.001f;
    position_ = map_.moved(base_, vel_ned_m_s_[0] * t_s, vel_ned_m_s_[1] * t_s);
    height_from_baro_ = baro.healthy && have_datum_;
    position_.alt_cm = height_from_baro_ ? baro_datum_cm_ + centimetres(baro.height_m)
                                         : base_.alt_cm - centimetres(vel_ned_m_s_[2] * t_s);
}

NorthEast Navigator::from_home_m() const {
    if (!home_set()) return NorthEast{0.0f, 0.0f};
    return map_.offset_m(home_, position_);
}

float Navigator::height_above_home_m() const {
    return home_set() ? (float)(position_.alt_cm - home_.alt_cm) * 0.01f : 0.0f;
}

void Navigator::take_home(const Location& home, const BaroReading& baro, HomeSource source) {
    home_ = home;
    home_source_ = source;
    ++home_changes_;
    map_.set_origin(home);
    // Home from the GPS ties the barometer to it: the height above home is then the
    // barometer's change since this moment.
    if (source == HomeSource::kGps && baro.healthy) {
        baro_datum_cm_ = home.alt_cm - centimetres(baro.height_m);
        have_datum_ = true;
    }
}

bool Navigator::set_home_here(const BaroReading& baro) {
    if (!have_position_) return false;
    take_home(position_, baro, HomeSource::kGroundStation);
    update(now_ms_, baro);
    return true;
}

bool Navigator::set_home(const Location& home, const BaroReading& baro) {
    if (home.lat_e7 < -900000000 || home.lat_e7 > 900000000 || home.lon_e7 < -1800000000 ||
        home.lon_e7 > 1800000000 || home.alt_cm < -100000 || home.alt_cm > 2000000)
        return false;
    take_home(home, baro, HomeSource::kGroundStation);
    if (have_position_) update(now_ms_, baro);
    return true;
}

}  // namespace nav
