#include "LinAlg.h"

namespace linalg {

float fast_atan2(float y, float x) {
    const float abs_y = y < 0.0f ? -y : y;
    const float abs_x = x < 0.0f ? -x : x;
    if (!(abs_x > 0.0f || abs_y > 0.0f)) return 0.0f;  // (0, 0) and NaN
    // Fold into the first octant: t = min/max in [0, 1].
    const bool steep = abs_y > abs_x;
    const float t = steep ? abs_x / abs_y : abs_y / abs_x;
    if (!is_finite(t)) return 0.0f;
    const float t2 = t * t;
    // Odd minimax polynomial, |error| <= 1.15e-5 rad on [0, 1].
    float a = t * (0.99986631f +
                   t2 * (-0.33030486f + t2 * (0.18015960f + t2 * (-0.08515681f + t2 * 0.02084534f))));
    if (steep) a = 0.5f * kPi - a;
    if (x < 0.0f) a = kPi - a;
    return y < 0.0f ? -a : a;
}

}  // namespace linalg
