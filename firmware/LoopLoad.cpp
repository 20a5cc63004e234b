// SPDX-License-Identifier: GPL-3.0-or-later
#include "LoopLoad.h"

#include "ArduinoCore.h"

namespace loop_load {

static uint32_t work_us = 0, window_start_us = 0;
static uint8_t load_pct = 0;

void start(uint32_t now_us) { window_start_us = now_us; }
void add_sample_work(uint32_t start_us, uint32_t end_us) { work_us += end_us - start_us; }
bool second_due() { return micros() - window_start_us >= 1000000u; }

void new_second() {
    const uint32_t now_us = micros();
    load_pct = (uint8_t)(work_us / ((now_us - window_start_us) / 100u));
    work_us = 0;
    window_start_us = now_us;
}

uint8_t percent() { return load_pct; }

}  // namespace loop_load
