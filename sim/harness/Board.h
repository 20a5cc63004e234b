// SPDX-License-Identifier: GPL-3.0-or-later
// The APM 2.5 board around a simavr ATmega2560 (../shared/SIM.md, ../shared/APM25.md):
// MPU6000 on SPI (CS pin 53 = PB0, INT on PE6), HMC5883L on TWI (7-bit 0x1E, DRDY on
// pin 31 = PC6), the MS5611 on SPI behind pin 40 = PG1 (its chip select watched), a
// u-blox GPS on UART1 (the GPS port), UART0 to a sink.
//
// simavr 1.6 corrections made here:
// - SPI: the SPDR write hook is replaced so a byte takes 8 x the configured SCK divider
//   in CPU cycles (simavr 1.6 charges a fixed 100 us).
// - TWI: after each TWCR write, simavr's pending TWI state timer (1 us per bit in 1.6)
//   is re-armed at the bit time TWBR/TWPS give: 16 + 2 * TWBR * 4^TWPS cycles per bit.
// - EEPROM: a write keeps EEPE set for the chip's 3.4 ms (simavr 1.6: no time at all).
// - ADC8..15 (MUX5): simavr 1.6 keeps values for ADC0..7 only; the harness converts the
//   others when ADCL is read (the battery's A12 and A13).
// - UART1: simavr 1.6 paces a character at 11 bit times (it counts a parity bit that
//   8N1 has not), slower than the GPS line: after each UBRR1L write the character time is
//   set to 10 bit times.
// - Time is avr->cycle / 16 MHz; the sensor models are advanced to it before every
//   bus byte and by a cycle timer at each of their events (at least every 1 ms); the
//   GPS line by its own timer at each character and event.
#pragma once

#include <stdint.h>

#include <cstdio>
#include <deque>
#include <memory>
#include <string>
#include <vector>

#include "BatteryModel.h"
#include "FaultSpec.h"
#include "Hmc5883Model.h"
#include "Mpu6000Model.h"
#include "Ms5611Model.h"
#include "RcLink.h"
#include "SerialLink.h"
#include "Trajectory.h"
#include "UartLine.h"
#include "UbloxModel.h"

struct avr_t;
struct avr_spi_t;
struct avr_irq_t;

namespace sim {

constexpr uint32_t kCpuHz = 16000000;
constexpr uint32_t kEepromSize = 4096;  // ATmega2560 datasheet 8.4: 4 KB EEPROM

struct BoardOptions {
    std::string elf_path;
    bool stamp = false;             // prefix each output line with the simulated time
    std::string input;              // bytes for UART0 RX
    double input_start_s = 2.5;     // latest start of the input (earlier: first angle line)
    bool input_start_fixed = false; // start exactly at input_start_s (--input-at)
    bool profile = false;
    std::string eeprom_path;        // --eeprom: the EEPROM's bytes at start and written back at exit
    const RcScript* rc = nullptr;   // --rc: the sticks, sent as PPM on ICP5 (PL1); none: PL1 untouched
    FILE* servo_log = nullptr;      // --servo-log: one row per pulse on OUT1-OUT8
    TcpSerial* serial = nullptr;    // --serial tcp:PORT: UART0 also to and from a TCP client
    bool measure_servos = false;    // the outputs' pulses measured even without a servo log
    double speed = 0.0;             // simulated seconds per wall second; 0: unpaced
    // --eeprom-cuts T1:T2:STEP: the EEPROM as a power cut at T1, T1+STEP, ... <= T2 leaves
    // it, written to eeprom_path.cut0, .cut1, ... (cuts_step_s 0: none)
    double eeprom_cuts_from_s = 0.0, eeprom_cuts_to_s = 0.0, eeprom_cuts_step_s = 0.0;
    // --mission: a QGC WPL 110 file written into the EEPROM's mission area before the run
    // (sim/models/MissionFile.h), on top of --eeprom's bytes or an erased chip.
    std::string mission_path;
    // --gps: the GPS module on UART1 (false: --gps none, nothing on the GPS port).
    bool gps_attached = true;
    UbloxOptions gps;
    // --baro: the MS5611 behind pin 40 (false: --baro none, nobody behind the chip select).
    bool baro_attached = true;
    Ms5611Options baro;
    // --battery: a pack behind the 3DR power module on A13 (voltage) and A12 (current);
    // without it those pins read 0 V. --battery-log: its truth at 10 Hz.
    bool battery_attached = false;
    BatteryOptions battery;
    FILE* battery_log = nullptr;
};

// What the GPS port carried, counted by the harness.
struct GpsPortCounters {
    uint32_t bytes_to_firmware = 0;       // characters raised on UART1 RX
    uint32_t framing_errors = 0;          // of them, with a low stop bit (garbage of a baud mismatch)
    uint32_t dropped_receiver_off = 0;    // module bytes on the line while RXEN1 was off (ignored)
    uint64_t held_chars = 0;              // character times a byte waited for simavr's RX FIFO (XOFF)
    uint32_t bytes_from_firmware = 0;     // UDR1 writes that went to the line
};

// Asks a running Board::run to return at its next instruction boundary (async-signal-safe:
// for SIGINT/SIGTERM handlers).
void request_stop();
bool stop_requested();

// Cycle counts between GPIOR0 (start) and GPIOR1 (end) writes of one section id
// (1..kMaxSectionId; other values are ignored).
constexpr int kMaxSectionId = 63;
struct SectionProfile {
    uint64_t count = 0, total = 0, min = UINT64_MAX, max = 0;
    uint64_t started_at = 0;
    bool open = false;
};

class Board {
public:
    Board(const Trajectory& trajectory, const BoardOptions& options);
    ~Board();

    // Loads the ELF and wires the parts; false with error() set on failure.
    bool init();
    const std::string& error() const { return error_; }

    // Runs until `seconds` of simulated time; false if the core crashed or stopped.
    bool run(double seconds);

    double time_s() const;
    Mpu6000Model& mpu() { return mpu_; }
    Hmc5883Model& mag() { return mag_; }
    BusFaults& bus_faults() { return bus_faults_; }
    UbloxModel* gps() { return gps_.get(); }   // null with --gps none
    Ms5611Model* baro() { return baro_.get(); } // null with --baro none
    BatteryModel* battery() { return battery_.get(); }  // null without --battery
    FaultTargets fault_targets();
    const GpsPortCounters& gps_port_counters() const { return gps_port_; }

    uint32_t bus_violations() const { return bus_violations_; }
    bool write_profile(const std::string& path) const;
    void print_counters(FILE* out) const;
    void finish_output();  // flushes a partial last line
    // Writes the EEPROM's kEepromSize bytes to options.eeprom_path (a no-op without one).
    bool save_eeprom();

    // simavr callbacks (static trampolines call these).
    void on_spdr_write(uint8_t value);
    void on_spi_byte_done();
    void on_port_change(char port, bool direction, uint8_t value);
    void on_twi_message(uint32_t value);
    void on_twcr_write(uint16_t addr, uint8_t value);
    void on_eecr_write(uint16_t addr, uint8_t value);
    void on_uart_byte(uint8_t byte);
    void on_uart1_byte(uint8_t byte);
    void on_ubrr1l_write(uint16_t addr, uint8_t value);
    uint64_t on_gps_tick();
    void set_uart1_held(bool held) { uart1_held_ = held; }
    uint64_t on_sensor_tick();
    uint64_t on_uart_input_tick();
    void on_uart_input_timer_ended() { input_timer_armed_ = false; }
    // simavr reset the core (the watchdog): the board's cycle timers again.
    void on_core_reset();
    uint64_t on_link_tick();
    void set_uart_input_held(bool held) { uart_input_held_ = held; }
    void on_gpior_write(bool end, uint8_t value);
    uint64_t on_ppm_edge();
    void on_servo_compare(int output, uint32_t value);
    void on_servo_pin();

    // What a servo on output 1..8 receives now (us; 0 when no pulse came in 3 periods).
    uint16_t servo_width_now_us(int output) const { return servo_pulses_.width_now_us(output, time_s(), 0.06); }
    // Appends a state to the sensor models' samples (--physics), and forgets those older
    // than `keep_s` before it.
    void append_sample(const TrajectorySample& sample, double keep_s);
    // The voltage on analog input A0 (ADC0), in millivolts: the airspeed sensor (--physics).
    void set_a0_mV(double mV);
    // The voltage on analog input A0..A15, in millivolts (A12, A13: the battery's).
    void set_adc_mV(int channel, double mV);
    uint8_t on_adcl_read(uint16_t addr);
    // After RcScript::push: restarts the PPM line if it had gone quiet.
    void rc_changed();

private:
    void advance_models();
    void advance_battery();
    void update_pins();
    bool mpu_selected() const;
    bool baro_deselected() const;
    void check_bus(const char* when);
    void start_input();
    void arm_input();
    bool load_eeprom();
    bool write_eeprom(const std::string& path) const;
    void take_eeprom_cuts();
    double uart1_bit_s() const;
    void arm_gps_timer();
    bool init_gps_port();
    uint8_t* eeprom_bytes() const;
    double sck_hz() const;
    bool init_rc();
    void init_servo_outputs();
    void schedule_ppm_edge();
    void write_servo_pulses(bool all);

    Mpu6000Model mpu_;
    Hmc5883Model mag_;
    BusFaults bus_faults_;
    BoardOptions options_;
    std::unique_ptr<UbloxModel> gps_;
    std::unique_ptr<Ms5611Model> baro_;
    std::unique_ptr<BatteryModel> battery_;
    double battery_t_s_ = 0.0;        // the pack's state is this time's
    double battery_log_next_s_ = 0.0;
    std::string error_;

    avr_t* avr_ = nullptr;
    avr_spi_t* spi_ = nullptr;
    void* twi_ = nullptr;
    avr_irq_t* twi_input_irq_ = nullptr;
    avr_irq_t* uart_input_irq_ = nullptr;
    avr_irq_t* mpu_int_irq_ = nullptr;
    avr_irq_t* mag_drdy_irq_ = nullptr;
    void (*twcr_original_)(avr_t*, uint16_t, uint8_t, void*) = nullptr;
    void* twcr_original_param_ = nullptr;
    void (*eecr_original_)(avr_t*, uint16_t, uint8_t, void*) = nullptr;
    uint8_t (*adcl_original_)(avr_t*, uint16_t, void*) = nullptr;
    void* adcl_original_param_ = nullptr;
    double adc_high_mV_[8] = {};  // ADC8..15 (simavr 1.6 keeps ADC0..7 only)
    void* eecr_original_param_ = nullptr;

    uint8_t spi_out_byte_ = 0;
    uint8_t port_b_ = 0, ddr_b_ = 0, port_g_ = 0, ddr_g_ = 0;
    bool mpu_cs_low_ = false;
    bool baro_cs_low_ = false;
    bool twi_selected_ = false;
    int int_level_ = -1, drdy_level_ = -1;
    uint32_t bus_violations_ = 0;
    uint32_t eeprom_cuts_taken_ = 0;

    std::string line_;
    bool first_angle_line_seen_ = false;
    bool input_started_ = false;
    bool uart_input_held_ = false;        // simavr's receive FIFO is full (XOFF)
    uint64_t uart_input_held_chars_ = 0;  // character times the input waited for it
    size_t input_pos_ = 0;
    uint64_t input_consumed_ = 0;         // bytes typed and dropped from `input` (a live client's)
    bool input_timer_armed_ = false;      // uart_input_timer is registered
    unsigned core_resets_ = 0;            // watchdog resets seen
    Pacer pacer_{0.0};

    // The GPS port (UART1): the firmware's USART1 receiving the module's line, and the
    // line the firmware sends on.
    avr_irq_t* uart1_input_irq_ = nullptr;
    void* uart1_ = nullptr;              // simavr's avr_uart_t for UART1
    void (*ubrr1l_original_)(avr_t*, uint16_t, uint8_t, void*) = nullptr;
    void* ubrr1l_original_param_ = nullptr;
    UartReceiver uart1_rx_;
    std::deque<UartChar> uart1_pending_;  // decoded, raised on RX at ready_s
    std::vector<UartChar> uart1_scratch_;
    double uart1_tx_free_s_ = 0.0;       // the firmware's TX line is busy until then
    bool uart1_held_ = false;            // simavr's RX FIFO is full (XOFF)
    uint64_t gps_timer_at_ = 0;          // the cycle the GPS timer is armed for (0: none)
    GpsPortCounters gps_port_;

    // --rc: the PPM line on PL1 (and Timer5's capture input when simavr does not wire it).
    std::unique_ptr<PpmEncoder> ppm_;
    PpmEdge ppm_next_;
    bool ppm_pending_ = false;         // a cycle timer is armed for ppm_next_
    avr_irq_t* ppm_pin_irq_ = nullptr;
    avr_irq_t* ppm_icp_irq_ = nullptr; // raised too when the ATmega2560 core leaves ICP5 unwired

    // --servo-log: the output-compare level of each output and the pulses measured.
    uint8_t servo_oc_level_[kServoOutputs] = {};
    ServoPulseLog servo_pulses_;
    std::vector<ServoPulse> servo_ready_;

    SectionProfile sections_[kMaxSectionId + 1];
    uint64_t run_first_start_ = 0, run_last_end_ = 0;
    bool run_started_ = false;
    uint32_t profile_errors_ = 0;
    uint32_t static_end_ = 0;  // the first SRAM address above .data and .bss
};

}  // namespace sim
