// SPDX-License-Identifier: GPL-3.0-or-later
#include "VehicleRecord.h"

#include "Params.h"

namespace record2 {

uint8_t header_byte(uint16_t sequence, uint8_t payload, uint8_t i) {
    switch (i) {
        case 0: return kMagic0;
        case 1: return kMagic1;
        case 2: return kVersion;
        case 3: return payload;
        case 4: return (uint8_t)(sequence & 0xFFu);
        default: return (uint8_t)(sequence >> 8);
    }
}

uint16_t slot_crc(const settings::Settings& s, uint16_t sequence, uint8_t payload) {
    uint16_t crc = settings::kCrc16Init;
    for (uint8_t i = 0; i < kHeaderSize; ++i) crc = settings::crc16_update(crc, header_byte(sequence, payload, i));
    return params::vehicle_crc(s, crc);
}

void encode(const settings::Settings& s, uint16_t sequence, uint8_t* out) {
    const uint8_t n = (uint8_t)params::vehicle_bytes();
    for (uint8_t i = 0; i < kHeaderSize; ++i) out[i] = header_byte(sequence, n, i);
    params::vehicle_part(s, 0, n, out + kHeaderSize);
    const uint16_t crc = settings::crc16(out, (uint16_t)(kHeaderSize + n));
    out[kHeaderSize + n] = (uint8_t)(crc & 0xFFu);
    out[kHeaderSize + n + 1u] = (uint8_t)(crc >> 8);
}

Result load(const uint8_t* b, uint16_t sequence, settings::Settings& s) {
    if (b[0] == 0xFFu && b[1] == 0xFFu) return Result::Missing;  // erased: never written
    const uint8_t n = b[3];
    if (b[0] != kMagic0 || b[1] != kMagic1 || n > kMaxPayload) return Result::BadCrc;
    const uint16_t stored = (uint16_t)(b[kHeaderSize + n] | (uint16_t)((uint16_t)b[kHeaderSize + n + 1u] << 8));
    if (stored != settings::crc16(b, (uint16_t)(kHeaderSize + n))) return Result::BadCrc;
    // Another save's (a firmware before this record saved the first one since).
    if ((uint16_t)(b[4] | (uint16_t)((uint16_t)b[5] << 8)) != sequence) return Result::Missing;
    // Another layout, or a later firmware's rows (after a downgrade): as the first record's
    // other versions, refused whole.
    if (b[2] != kVersion || n > params::vehicle_bytes()) return Result::OldVersion;
    const settings::VehicleSettings before = s.vehicle;
    const int16_t before_centideg = s.declination_centideg;
    params::decode_vehicle(b + kHeaderSize, n, s);
    settings::set_declination_rad(s, s.vehicle.compass_dec_rad);  // the first record's copy from the float
    if (!settings::is_valid(s)) {
        s.vehicle = before;
        s.declination_centideg = before_centideg;
        return Result::BadValue;
    }
    return Result::Paired;
}

}  // namespace record2
