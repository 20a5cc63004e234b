// SPDX-License-Identifier: GPL-3.0-or-later
#include "UbxProtocol.h"

namespace gps {
namespace ubx {

uint8_t write_frame(uint8_t* out, uint8_t cls, uint8_t id, const uint8_t* payload, uint8_t payload_len) {
    out[0] = kSync1;
    out[1] = kSync2;
    out[2] = cls;
    out[3] = id;
    out[4] = payload_len;
    out[5] = 0;
    for (uint8_t i = 0; i < payload_len; ++i) out[6 + i] = payload[i];
    Checksum ck;
    ck.add(out + 2, (size_t)payload_len + 4u);
    out[6 + payload_len] = ck.a;
    out[7 + payload_len] = ck.b;
    return (uint8_t)(payload_len + kFrameOverhead);
}

}  // namespace ubx
}  // namespace gps
