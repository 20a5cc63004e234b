// SPDX-License-Identifier: GPL-3.0-or-later
#include "Board.h"
#include "MissionFile.h"

#include "Hmc5883Registers.h"
#include "Profile.h"

#include <unistd.h>

#include <cmath>
#include <csignal>
#include <cstdarg>
#include <cstring>
#include <algorithm>

#include "avr_adc.h"
#include "avr_eeprom.h"
#include "avr_extint.h"
#include "avr_ioport.h"
#include "avr_spi.h"
#include "avr_timer.h"
#include "avr_twi.h"
#include "avr_uart.h"
#include "sim_avr.h"
#include "sim_elf.h"
#include "sim_interrupts.h"
#include "sim_irq.h"
#include "sim_regbit.h"

namespace sim {

namespace {

// ATmega2560 data-space addresses (datasheet "Register Summary"; I/O address + 0x20).
constexpr uint16_t kSpdr = 0x4E;
constexpr uint16_t kTwbr = 0xB8;
constexpr uint16_t kTwsr = 0xB9;
constexpr uint16_t kTwcr = 0xBC;
constexpr uint16_t kEecr = 0x3F;     // EEPROM control (datasheet 8.6.3)
constexpr uint8_t kEepe = 1u << 1;   // EEPROM write enable: set while a write is in progress
constexpr uint8_t kEempe = 1u << 2;  // EEPROM master write enable
// Datasheet table 8-1: erase and write in one operation (EEPM = 00, what avr-libc's
// eeprom_update_byte uses) takes 3.4 ms.
constexpr double kEepromWrite_s = 3.4e-3;
constexpr uint16_t kUcsr0a = 0xC0;
constexpr uint16_t kUbrr0l = 0xC4;
constexpr uint16_t kUbrr0h = 0xC5;
// UART1, the GPS port (datasheet "Register Summary").
constexpr uint16_t kUcsr1a = 0xC8;
constexpr uint16_t kUcsr1b = 0xC9;
constexpr uint16_t kUbrr1l = 0xCC;
constexpr uint16_t kUbrr1h = 0xCD;
constexpr uint8_t kU2x = 1u << 1;    // UCSRnA
constexpr uint8_t kRxen = 1u << 4;   // UCSRnB
constexpr uint16_t kSpcr = 0x4C;     // SPI control: CPOL bit 3, CPHA bit 2
constexpr uint16_t kGpior0 = 0x3E;  // profiling: section start
constexpr uint16_t kGpior1 = 0x4A;  // profiling: section end
constexpr uint16_t kAdcl = 0x78;    // ADC data low, high at 0x79 (datasheet 26.8.3)
constexpr uint16_t kAdcsrb = 0x7B;  // MUX5: bit 3
constexpr uint16_t kAdmux = 0x7C;   // REFS1:0 bits 7:6, MUX4:0 bits 4:0
constexpr uint8_t kMpuCsBit = 0;    // PB0, Arduino pin 53
constexpr uint8_t kBaroCsBit = 1;   // PG1, Arduino pin 40
constexpr uint32_t kSramStart = 0x200;  // ATmega2560: SRAM after the 512 register and I/O addresses
constexpr int kMaxViolationsPrinted = 10;

// The servo outputs as the APM 2.5 wires them (APM25.md "Flying", ArduPilot's APM2 HAL):
// the timer, its compare unit (0 A, 1 B, 2 C), the port and bit of the OCnx pin, and
// TCCRnA's data address, whose COMnx1:0 bits (A 7:6, B 5:4, C 3:2) connect the pin.
struct ServoOutputPin {
    char timer;
    int compare;
    char port;
    uint8_t bit;
    uint16_t tccra;
    uint16_t ddr, port_reg;
};
constexpr ServoOutputPin kServoPins[kServoOutputs] = {
    {'1', 1, 'B', 6, 0x80, 0x24, 0x25},   // OUT1 OC1B PB6
    {'1', 0, 'B', 5, 0x80, 0x24, 0x25},   // OUT2 OC1A PB5
    {'4', 2, 'H', 5, 0xA0, 0x101, 0x102}, // OUT3 OC4C PH5
    {'4', 1, 'H', 4, 0xA0, 0x101, 0x102}, // OUT4 OC4B PH4
    {'4', 0, 'H', 3, 0xA0, 0x101, 0x102}, // OUT5 OC4A PH3
    {'3', 2, 'E', 5, 0x90, 0x2D, 0x2E},   // OUT6 OC3C PE5
    {'3', 1, 'E', 4, 0x90, 0x2D, 0x2E},   // OUT7 OC3B PE4
    {'3', 0, 'E', 3, 0x90, 0x2D, 0x2E},   // OUT8 OC3A PE3
};
constexpr uint8_t kPpmBit = 1;  // ICP5 = PL1, Arduino pin 48

Board* g_board = nullptr;  // simavr's logger has no context pointer

void log_to_stderr(avr_t*, const int level, const char* format, va_list args) {
    if (level <= LOG_WARNING) vfprintf(stderr, format, args);
}

void no_sleep(avr_t*, avr_cycle_count_t) {}

void spdr_write_hook(avr_t*, avr_io_addr_t, uint8_t v, void* param) {
    static_cast<Board*>(param)->on_spdr_write(v);
}
avr_cycle_count_t spi_done_timer(avr_t*, avr_cycle_count_t, void* param) {
    static_cast<Board*>(param)->on_spi_byte_done();
    return 0;
}
void eecr_write_hook(avr_t*, avr_io_addr_t addr, uint8_t v, void* param) {
    static_cast<Board*>(param)->on_eecr_write(addr, v);
}
avr_cycle_count_t eeprom_done_timer(avr_t* avr, avr_cycle_count_t, void*) {
    avr->data[kEecr] = (uint8_t)(avr->data[kEecr] & ~kEepe);
    return 0;
}
uint8_t adcl_read_hook(avr_t*, avr_io_addr_t addr, void* param) {
    return static_cast<Board*>(param)->on_adcl_read(addr);
}

void twcr_write_hook(avr_t*, avr_io_addr_t addr, uint8_t v, void* param) {
    static_cast<Board*>(param)->on_twcr_write(addr, v);
}
void twi_output_hook(avr_irq_t*, uint32_t value, void* param) {
    static_cast<Board*>(param)->on_twi_message(value);
}
void uart_output_hook(avr_irq_t*, uint32_t value, void* param) {
    static_cast<Board*>(param)->on_uart_byte((uint8_t)value);
}
void uart1_output_hook(avr_irq_t*, uint32_t value, void* param) {
    static_cast<Board*>(param)->on_uart1_byte((uint8_t)value);
}
void uart1_xoff_hook(avr_irq_t*, uint32_t, void* param) { static_cast<Board*>(param)->set_uart1_held(true); }
void uart1_xon_hook(avr_irq_t*, uint32_t, void* param) { static_cast<Board*>(param)->set_uart1_held(false); }
void ubrr1l_write_hook(avr_t*, avr_io_addr_t addr, uint8_t v, void* param) {
    static_cast<Board*>(param)->on_ubrr1l_write(addr, v);
}
avr_cycle_count_t gps_timer(avr_t*, avr_cycle_count_t, void* param) {
    return static_cast<Board*>(param)->on_gps_tick();
}
avr_cycle_count_t sensor_timer(avr_t*, avr_cycle_count_t, void* param) {
    return static_cast<Board*>(param)->on_sensor_tick();
}
// simavr's UART says XOFF when its 64-byte receive FIFO is full and XON when there is
// room again (avr_uart.h).
void uart_xoff_hook(avr_irq_t*, uint32_t, void* param) { static_cast<Board*>(param)->set_uart_input_held(true); }
void uart_xon_hook(avr_irq_t*, uint32_t, void* param) { static_cast<Board*>(param)->set_uart_input_held(false); }

avr_cycle_count_t uart_input_timer(avr_t*, avr_cycle_count_t, void* param) {
    Board* board = static_cast<Board*>(param);
    const uint64_t next = board->on_uart_input_tick();
    if (next == 0) board->on_uart_input_timer_ended();
    return next;
}
avr_cycle_count_t link_timer(avr_t*, avr_cycle_count_t, void* param) {
    return static_cast<Board*>(param)->on_link_tick();
}
volatile std::sig_atomic_t g_stop_requested = 0;
// simavr's avr_reset (the watchdog's reset: the firmware's reboot command) clears every
// cycle timer: the core's reset hook re-arms the board's own (sensors, link, GPS, PPM).
Board* g_reset_board = nullptr;
void (*g_core_reset)(avr_t*) = nullptr;
void core_reset_hook(avr_t* avr) {
    if (g_core_reset) g_core_reset(avr);
    if (g_reset_board) g_reset_board->on_core_reset();
}
avr_cycle_count_t uart_input_start_timer(avr_t*, avr_cycle_count_t, void* param) {
    static_cast<Board*>(param)->on_uart_input_tick();  // starts the input if not yet
    return 0;
}
void gpior_write_hook(avr_t* avr, avr_io_addr_t addr, uint8_t v, void* param) {
    avr->data[addr] = v;
    static_cast<Board*>(param)->on_gpior_write(addr == kGpior1, v);
}

avr_cycle_count_t ppm_edge_timer(avr_t*, avr_cycle_count_t, void* param) {
    return static_cast<Board*>(param)->on_ppm_edge();
}

struct ServoHook {
    Board* board;
    int output;  // 1..8
};
ServoHook g_servo_hooks[kServoOutputs];
void servo_compare_hook(avr_irq_t*, uint32_t value, void* param) {
    const ServoHook* hook = static_cast<ServoHook*>(param);
    hook->board->on_servo_compare(hook->output, value);
}
void servo_pin_hook(avr_irq_t*, uint32_t, void* param) { static_cast<Board*>(param)->on_servo_pin(); }

// simavr's timer module for Timer n ('5' ...): the io list holds each module, an
// avr_timer_t begins with its avr_io_t.
avr_timer_t* find_timer(avr_t* avr, char name) {
    for (avr_io_t* port = avr->io_port; port != nullptr; port = port->next) {
        if (port->kind == nullptr || std::strcmp(port->kind, "timer") != 0) continue;
        avr_timer_t* timer = reinterpret_cast<avr_timer_t*>(port);
        if (timer->name == name) return timer;
    }
    return nullptr;
}

struct PortHook {
    Board* board;
    char port;
    bool direction;
};
PortHook g_port_hooks[4];
void port_hook(avr_irq_t*, uint32_t value, void* param) {
    const PortHook* hook = static_cast<PortHook*>(param);
    hook->board->on_port_change(hook->port, hook->direction, (uint8_t)value);
}

}  // namespace

void request_stop() { g_stop_requested = 1; }
bool stop_requested() { return g_stop_requested != 0; }

Board::Board(const Trajectory& trajectory, const BoardOptions& options)
    : mpu_(trajectory), mag_(trajectory), options_(options) {
    if (options_.gps_attached) gps_.reset(new UbloxModel(trajectory, options_.gps));
    if (options_.baro_attached) baro_.reset(new Ms5611Model(trajectory, options_.baro));
    if (options_.battery_attached) battery_.reset(new BatteryModel(options_.battery));
}

FaultTargets Board::fault_targets() {
    FaultTargets t;
    t.mpu = &mpu_;
    t.mag = &mag_;
    t.bus = &bus_faults_;
    t.gps = gps_ ? &gps_->faults() : nullptr;
    t.baro = baro_ ? &baro_->faults() : nullptr;
    return t;
}

Board::~Board() {
    if (avr_) avr_terminate(avr_);
    if (g_board == this) g_board = nullptr;
}

double Board::time_s() const { return avr_ ? (double)avr_->cycle / (double)kCpuHz : 0.0; }

bool Board::init() {
    g_board = this;
    avr_global_logger_set(log_to_stderr);
    elf_firmware_t firmware;
    std::memset(&firmware, 0, sizeof firmware);
    if (elf_read_firmware(options_.elf_path.c_str(), &firmware) != 0) {
        error_ = "cannot read the ELF '" + options_.elf_path + "'";
        return false;
    }
    // Arduino ELFs carry no .mmcu section (SIM.md): the board is fixed.
    std::strcpy(firmware.mmcu, "atmega2560");
    // Static data (.data then .bss) from the start of SRAM: above it, the free RAM the
    // firmware paints at start-up (lib/LinAlg/Profile.h kStackPaint), then the stack.
    static_end_ = kSramStart + firmware.datasize + firmware.bsssize;
    firmware.frequency = kCpuHz;

    // simavr 1.6 prints part-init chatter on stdout: keep stdout for the firmware's bytes.
    fflush(stdout);
    const int saved_stdout = dup(1);
    dup2(2, 1);
    avr_ = avr_make_mcu_by_name(firmware.mmcu);
    if (avr_) {
        avr_init(avr_);
        avr_load_firmware(avr_, &firmware);
    }
    fflush(stdout);
    dup2(saved_stdout, 1);
    close(saved_stdout);
    if (!avr_) {
        error_ = "simavr does not know the atmega2560";
        return false;
    }
    avr_->frequency = kCpuHz;
    // The APM 2.5's ATmega2560 runs at 5 V, AVCC and the default reference too (simavr's
    // default: 3.3 V); only the ADC reads these.
    avr_->vcc = avr_->avcc = avr_->aref = 5000;
    if (!load_eeprom()) return false;
    avr_->sleep = no_sleep;  // else simavr sleeps in wall-clock time when the core idles
    g_reset_board = this;
    g_core_reset = avr_->reset;
    avr_->reset = core_reset_hook;
    avr_->log = LOG_WARNING;

    // External interrupts INT0-7: a low level raises its interrupt once, not again at every
    // cycle while it stays low. simavr's "strict" level triggering polls each pin every
    // cycle while it is low, enabled or not, in level mode (ISC 00, the reset value): the
    // servo outputs on INT4/INT5 (OUT7/OUT6, low 90 % of the time) cost a third of the
    // simulation's time. The firmware uses no level-triggered interrupt.
    for (uint8_t extint = 0; extint < 8; ++extint) avr_extint_set_strict_lvl_trig(avr_, extint, 0);

    // UART0: no stdio echo, no sleep on RX poll (SIM.md).
    uint32_t uart_flags = 0;
    avr_ioctl(avr_, AVR_IOCTL_UART_GET_FLAGS('0'), &uart_flags);
    uart_flags &= ~(uint32_t)(AVR_UART_FLAG_STDIO | AVR_UART_FLAG_POLL_SLEEP);
    avr_ioctl(avr_, AVR_IOCTL_UART_SET_FLAGS('0'), &uart_flags);
    avr_irq_register_notify(avr_io_getirq(avr_, AVR_IOCTL_UART_GETIRQ('0'), UART_IRQ_OUTPUT), uart_output_hook,
                            this);
    uart_input_irq_ = avr_io_getirq(avr_, AVR_IOCTL_UART_GETIRQ('0'), UART_IRQ_INPUT);
    avr_irq_register_notify(avr_io_getirq(avr_, AVR_IOCTL_UART_GETIRQ('0'), UART_IRQ_OUT_XOFF), uart_xoff_hook, this);
    avr_irq_register_notify(avr_io_getirq(avr_, AVR_IOCTL_UART_GETIRQ('0'), UART_IRQ_OUT_XON), uart_xon_hook, this);
    // UART1 (the GPS port) the same: no stdio echo of what the firmware sends the GPS, no
    // sleep when the firmware polls it.
    avr_ioctl(avr_, AVR_IOCTL_UART_GET_FLAGS('1'), &uart_flags);
    uart_flags &= ~(uint32_t)(AVR_UART_FLAG_STDIO | AVR_UART_FLAG_POLL_SLEEP);
    avr_ioctl(avr_, AVR_IOCTL_UART_SET_FLAGS('1'), &uart_flags);
    if (gps_ && !init_gps_port()) return false;

    // SPI: take over the SPDR write so a byte lasts what the configured clock says.
    spi_ = static_cast<avr_spi_t*>(avr_->io[AVR_DATA_TO_IO(kSpdr)].w.param);
    if (!spi_ || spi_->r_spdr != kSpdr) {
        error_ = "simavr's SPI is not where this harness expects it (SPDR hook)";
        return false;
    }
    avr_->io[AVR_DATA_TO_IO(kSpdr)].w.c = spdr_write_hook;
    avr_->io[AVR_DATA_TO_IO(kSpdr)].w.param = this;

    // TWI: the HMC5883L answers simavr's TWI messages; TWCR writes get the bit time fixed.
    twi_input_irq_ = avr_io_getirq(avr_, AVR_IOCTL_TWI_GETIRQ(0), TWI_IRQ_INPUT);
    avr_irq_register_notify(avr_io_getirq(avr_, AVR_IOCTL_TWI_GETIRQ(0), TWI_IRQ_OUTPUT), twi_output_hook, this);
    twcr_original_ = avr_->io[AVR_DATA_TO_IO(kTwcr)].w.c;
    twcr_original_param_ = avr_->io[AVR_DATA_TO_IO(kTwcr)].w.param;
    twi_ = twcr_original_param_;
    if (twcr_original_) {
        avr_->io[AVR_DATA_TO_IO(kTwcr)].w.c = twcr_write_hook;
        avr_->io[AVR_DATA_TO_IO(kTwcr)].w.param = this;
    }

    // ADC8..ADC15: simavr 1.6 keeps a value for ADC0..7 only and reads past its table for
    // the others (MUX5 set): the ADCL read hook converts those channels here.
    adcl_original_ = avr_->io[AVR_DATA_TO_IO(kAdcl)].r.c;
    adcl_original_param_ = avr_->io[AVR_DATA_TO_IO(kAdcl)].r.param;
    if (adcl_original_) {
        avr_->io[AVR_DATA_TO_IO(kAdcl)].r.c = adcl_read_hook;
        avr_->io[AVR_DATA_TO_IO(kAdcl)].r.param = this;
    }

    // EEPROM: a write keeps EEPE set for the chip's write time (simavr 1.6: no time).
    eecr_original_ = avr_->io[AVR_DATA_TO_IO(kEecr)].w.c;
    eecr_original_param_ = avr_->io[AVR_DATA_TO_IO(kEecr)].w.param;
    if (eecr_original_) {
        avr_->io[AVR_DATA_TO_IO(kEecr)].w.c = eecr_write_hook;
        avr_->io[AVR_DATA_TO_IO(kEecr)].w.param = this;
    }

    // Chip selects: PORTB/DDRB and PORTG/DDRG register writes.
    const char ports[2] = {'B', 'G'};
    for (int i = 0; i < 2; ++i) {
        g_port_hooks[2 * i] = PortHook{this, ports[i], false};
        g_port_hooks[2 * i + 1] = PortHook{this, ports[i], true};
        avr_irq_register_notify(avr_io_getirq(avr_, AVR_IOCTL_IOPORT_GETIRQ(ports[i]), IOPORT_IRQ_REG_PORT),
                                port_hook, &g_port_hooks[2 * i]);
        avr_irq_register_notify(avr_io_getirq(avr_, AVR_IOCTL_IOPORT_GETIRQ(ports[i]), IOPORT_IRQ_DIRECTION_ALL),
                                port_hook, &g_port_hooks[2 * i + 1]);
    }
    mpu_int_irq_ = avr_io_getirq(avr_, AVR_IOCTL_IOPORT_GETIRQ('E'), 6);
    mag_drdy_irq_ = avr_io_getirq(avr_, AVR_IOCTL_IOPORT_GETIRQ('C'), 6);

    if (options_.profile) {
        avr_register_io_write(avr_, kGpior0, gpior_write_hook, this);
        avr_register_io_write(avr_, kGpior1, gpior_write_hook, this);
    }

    if (!init_rc()) return false;
    if (options_.servo_log || options_.measure_servos || battery_) init_servo_outputs();
    if (battery_) {
        if (options_.battery_log) std::fputs("t,volts,amps,mah,charge\n", options_.battery_log);
        advance_battery();
    }

    avr_cycle_timer_register(avr_, 1, sensor_timer, this);
    if (options_.serial || options_.speed > 0.0) {
        pacer_ = Pacer(options_.speed);
        avr_cycle_timer_register(avr_, 1, link_timer, this);
    }
    // A client's bytes go to RX as they come; a --input file still waits for its start.
    if (options_.serial && options_.input.empty()) start_input();
    if (!options_.input.empty()) {
        avr_cycle_timer_register(avr_, (avr_cycle_count_t)(options_.input_start_s * kCpuHz), uart_input_start_timer,
                                 this);
    }
    update_pins();
    return true;
}

void Board::on_core_reset() {
    ++core_resets_;
    std::fprintf(stderr, "apm25sim: t=%.6f s: the AVR was reset (watchdog)\n", time_s());
    avr_cycle_timer_register(avr_, 1, sensor_timer, this);
    if (options_.serial || options_.speed > 0.0) avr_cycle_timer_register(avr_, 1, link_timer, this);
    input_timer_armed_ = false;
    gps_timer_at_ = 0;
    if (gps_) arm_gps_timer();
    ppm_pending_ = false;
    schedule_ppm_edge();
}

bool Board::run(double seconds) {
    const avr_cycle_count_t end = (avr_cycle_count_t)std::llround(seconds * kCpuHz);
    while (avr_->cycle < end && !g_stop_requested) {
        if (options_.eeprom_cuts_step_s > 0.0) take_eeprom_cuts();
        const int state = avr_run(avr_);
        if (state == cpu_Done || state == cpu_Crashed) {
            error_ = state == cpu_Crashed ? "the AVR core crashed" : "the AVR core stopped";
            char where[64];
            std::snprintf(where, sizeof where, " at t=%.6f s, PC=0x%05x", time_s(), (unsigned)avr_->pc);
            error_ += where;
            return false;
        }
    }
    return true;
}

// --- time and pins ------------------------------------------------------------

void Board::advance_models() {
    const double t_s = time_s();
    mpu_.advance_to(t_s);
    mag_.advance_to(t_s);
    if (baro_) baro_->advance_to(t_s);
}

// The pack (BatteryModel.h) run to now at the current the throttle on OUT3 asks for now
// (or its fixed one), and its power module's outputs on A13 and A12: simavr's ADC
// converts the millivolts last raised on a channel's IRQ. Called by the sensor timer,
// at least every 1 ms.
void Board::advance_battery() {
    const double t_s = time_s();
    const double amps = battery_->current_a(servo_width_now_us(3));
    battery_->step(t_s - battery_t_s_, amps);
    battery_t_s_ = t_s;
    set_adc_mV(13, battery_->volt_pin_mV());
    set_adc_mV(12, battery_->curr_pin_mV());
    if (options_.battery_log && t_s >= battery_log_next_s_) {
        std::fprintf(options_.battery_log, "%.3f,%.4f,%.4f,%.4f,%.6f\n", t_s, battery_->voltage_v(),
                     battery_->current_a(), battery_->consumed_mah(), battery_->charge());
        battery_log_next_s_ += 0.1;
    }
}

void Board::update_pins() {
    const int int_level = mpu_.int_pin_high() ? 1 : 0;
    if (int_level != int_level_) {
        int_level_ = int_level;
        avr_raise_irq(mpu_int_irq_, (uint32_t)int_level);
    }
    const int drdy_level = mag_.drdy_pin_high() ? 1 : 0;
    if (drdy_level != drdy_level_) {
        drdy_level_ = drdy_level;
        avr_raise_irq(mag_drdy_irq_, (uint32_t)drdy_level);
    }
}

uint64_t Board::on_sensor_tick() {
    advance_models();
    if (battery_) advance_battery();
    update_pins();
    // Next: the earliest model event, at least every 1 ms (fault windows, pulse ends).
    const double now_s = time_s();
    double next_s = now_s + 1e-3;
    if (mpu_.next_event_s() < next_s) next_s = mpu_.next_event_s();
    if (mag_.next_event_s() < next_s) next_s = mag_.next_event_s();
    uint64_t next_cycle = (uint64_t)std::ceil(next_s * kCpuHz);
    if (next_cycle <= avr_->cycle) next_cycle = avr_->cycle + 1;
    return next_cycle;
}

// --- SPI ----------------------------------------------------------------------

double Board::sck_hz() const {
    static const unsigned kDivider[4] = {4, 16, 64, 128};  // SPR1:SPR0 (datasheet 21.5.1)
    const unsigned spr = (unsigned)avr_regbit_get(avr_, spi_->spr[0]) | ((unsigned)avr_regbit_get(avr_, spi_->spr[1]) << 1);
    unsigned divider = kDivider[spr];
    if (avr_regbit_get(avr_, spi_->spr[2])) divider /= 2;  // SPI2X
    return (double)kCpuHz / divider;
}

void Board::on_spdr_write(uint8_t value) {
    // As the hardware: writing SPDR clears SPIF and starts shifting 8 bits at SCK.
    avr_core_watch_write(avr_, kSpdr, value);
    avr_regbit_clear(avr_, spi_->spi.raised);
    if (!avr_regbit_get(avr_, spi_->spe) || !avr_regbit_get(avr_, spi_->mstr)) return;
    spi_out_byte_ = value;
    const avr_cycle_count_t cycles = (avr_cycle_count_t)std::llround(8.0 * kCpuHz / sck_hz());
    avr_cycle_timer_register(avr_, cycles, spi_done_timer, this);
}

void Board::on_spi_byte_done() {
    advance_models();
    check_bus("during an SPI transfer");
    uint8_t miso = 0x00;  // nobody drives MISO
    if (mpu_cs_low_) miso = mpu_.transfer(spi_out_byte_, sck_hz());
    // The MS5611 answers only while pin 40 is low (with pin 53 low too, a violation
    // reported above, both drive MISO: the bus reads their AND).
    if (baro_ && baro_cs_low_) {
        const int mode = (avr_->data[kSpcr] >> 2) & 0x03;  // CPOL:CPHA
        const uint8_t baro_miso = baro_->transfer(spi_out_byte_, mode);
        miso = mpu_cs_low_ ? (uint8_t)(miso & baro_miso) : baro_miso;
    }
    // simavr's SPI input sets the received byte and raises SPIF (as its own completion).
    avr_raise_irq(spi_->io.irq + SPI_IRQ_INPUT, miso);
    update_pins();
}

bool Board::mpu_selected() const { return (ddr_b_ & (1u << kMpuCsBit)) && !(port_b_ & (1u << kMpuCsBit)); }

// Pin 40 high: driven high, or (input) held by the pull-up the PORT bit enables.
bool Board::baro_deselected() const { return (port_g_ & (1u << kBaroCsBit)) != 0; }

void Board::check_bus(const char* when) {
    if (!mpu_cs_low_ || baro_deselected()) return;
    ++bus_violations_;
    if (bus_violations_ <= (uint32_t)kMaxViolationsPrinted) {
        std::fprintf(stderr,
                     "apm25sim: bus violation at t=%.6f s (PC=0x%05x): MPU6000 chip select (pin 53) low "
                     "while the barometer chip select (pin 40) is not high, %s\n",
                     time_s(), (unsigned)avr_->pc, when);
    }
}

void Board::on_port_change(char port, bool direction, uint8_t value) {
    if (port == 'B') (direction ? ddr_b_ : port_b_) = value;
    if (port == 'G') (direction ? ddr_g_ : port_g_) = value;
    // Pin 40 low (an output driven low): the MS5611 is selected.
    const bool baro_selected = (ddr_g_ & (1u << kBaroCsBit)) && !(port_g_ & (1u << kBaroCsBit));
    if (baro_selected != baro_cs_low_) {
        advance_models();
        baro_cs_low_ = baro_selected;
        if (baro_) baro_->set_chip_select(baro_selected);
    }
    const bool selected = mpu_selected();
    if (selected != mpu_cs_low_) {
        advance_models();
        mpu_cs_low_ = selected;
        mpu_.set_chip_select(selected);
        if (selected) check_bus("when pin 53 went low");
        update_pins();
    } else if (port == 'G' && mpu_cs_low_) {
        check_bus("when pin 40 changed");
    }
}

// --- TWI ----------------------------------------------------------------------

// simavr 1.6 writes the EEPROM byte at once and clears EEPE in the same instant; the
// chip is busy for kEepromWrite_s, EEPE reading 1 (datasheet 8.6.3), which is what
// eeprom_is_ready() and avr-libc's busy-wait see. The byte itself is in the EEPROM
// from the start: a run that ends during the write keeps it (a cut is byte-exact).
void Board::on_eecr_write(uint16_t addr, uint8_t value) {
    const bool starts_write = (value & kEepe) && (avr_->data[kEecr] & kEempe) && !(avr_->data[kEecr] & kEepe);
    eecr_original_(avr_, addr, value, eecr_original_param_);
    if (!starts_write) return;
    avr_->data[kEecr] = (uint8_t)(avr_->data[kEecr] | kEepe);
    avr_cycle_timer_register(avr_, (avr_cycle_count_t)std::llround(kEepromWrite_s * kCpuHz), eeprom_done_timer, this);
}

void Board::on_twcr_write(uint16_t addr, uint8_t value) {
    // Timers simavr's TWI already had pending, so only the new one is re-timed.
    std::vector<avr_cycle_count_t> before;
    for (avr_cycle_timer_slot_p slot = avr_->cycle_timers.timer; slot; slot = slot->next)
        if (slot->param == twi_) before.push_back(slot->when);
    twcr_original_(avr_, addr, value, twcr_original_param_);

    // simavr 1.6 arms the next TWI state after N "bits" of 1 us; the bus takes
    // N x (16 + 2 TWBR 4^TWPS) CPU cycles (ATmega2560 datasheet 24.5.2).
    const unsigned prescaler = avr_->data[kTwsr] & 0x03;
    const uint64_t cycles_per_bit = 16u + 2u * (uint64_t)avr_->data[kTwbr] * (1u << (2 * prescaler));
    struct Pending {
        avr_cycle_timer_t timer;
        avr_cycle_count_t when;
    };
    std::vector<Pending> fresh;
    for (avr_cycle_timer_slot_p slot = avr_->cycle_timers.timer; slot; slot = slot->next) {
        if (slot->param != twi_) continue;
        bool old = false;
        for (avr_cycle_count_t w : before) old = old || w == slot->when;
        if (!old) fresh.push_back(Pending{slot->timer, slot->when});
    }
    for (const Pending& p : fresh) {
        const uint64_t delay = p.when > avr_->cycle ? p.when - avr_->cycle : 0;
        const uint64_t bits = (delay + kCpuHz / 2000000) / (kCpuHz / 1000000);
        if (bits == 0) continue;
        avr_cycle_timer_cancel(avr_, p.timer, twi_);
        avr_cycle_timer_register(avr_, bits * cycles_per_bit, p.timer, twi_);
    }
}

void Board::on_twi_message(uint32_t value) {
    avr_twi_msg_irq_t msg;
    msg.u.v = value;
    const uint8_t cond = msg.u.twi.msg;
    const uint8_t addr = msg.u.twi.addr;
    advance_models();
    if (cond & TWI_COND_STOP) {
        if (twi_selected_) mag_.stop();
        twi_selected_ = false;
    }
    if (cond & TWI_COND_START) {
        if (twi_selected_) mag_.stop();  // repeated start
        twi_selected_ = false;
        const bool bus_ok = !bus_faults_.i2c_sda_low.active(time_s());
        if (bus_ok && (addr >> 1) == hmc5883::kAddress7 && mag_.start((addr & 1) != 0)) {
            twi_selected_ = true;
            avr_raise_irq(twi_input_irq_, avr_twi_irq_msg(TWI_COND_ACK, addr, 1));
        }
    }
    if (twi_selected_ && (cond & TWI_COND_WRITE)) {
        if (mag_.write(msg.u.twi.data)) avr_raise_irq(twi_input_irq_, avr_twi_irq_msg(TWI_COND_ACK, addr, 1));
    }
    if (twi_selected_ && (cond & TWI_COND_READ)) {
        const uint8_t byte = mag_.read();
        avr_raise_irq(twi_input_irq_, avr_twi_irq_msg(TWI_COND_READ, addr, byte));
    }
    update_pins();
}

// --- UART ---------------------------------------------------------------------

void Board::on_uart_byte(uint8_t byte) {
    if (options_.serial) options_.serial->send(byte);
    if (!options_.stamp) std::fputc(byte, stdout);
    if (byte == '\n') {
        if (options_.stamp) {
            std::printf("%.6f ", time_s());
            std::fwrite(line_.data(), 1, line_.size(), stdout);
            std::fputc('\n', stdout);
        }
        const bool angle_line = !line_.empty() && line_[0] != '#' && line_[0] != '\r';
        line_.clear();
        if (angle_line && !first_angle_line_seen_) {
            first_angle_line_seen_ = true;
            if (!options_.input_start_fixed) start_input();
        }
        return;
    }
    line_.push_back((char)byte);
}

void Board::finish_output() {
    write_servo_pulses(true);
    if (options_.servo_log) std::fflush(options_.servo_log);
    if (options_.stamp && !line_.empty()) {
        std::printf("%.6f ", time_s());
        std::fwrite(line_.data(), 1, line_.size(), stdout);
        line_.clear();
    }
    std::fflush(stdout);
}

void Board::start_input() {
    if (input_started_ || (options_.input.empty() && !options_.serial)) return;
    input_started_ = true;
    arm_input();
}

void Board::arm_input() {
    if (input_timer_armed_ || input_pos_ >= options_.input.size()) return;
    input_timer_armed_ = true;
    avr_cycle_timer_register(avr_, 1, uart_input_timer, this);
}

// Every millisecond of simulated time: the TCP client's bytes in and out, and the wait
// that keeps simulated time from running ahead of the wall clock.
uint64_t Board::on_link_tick() {
    pacer_.wait_until(time_s());
    if (options_.serial) {
        std::string received;
        const std::string event = options_.serial->poll(received);
        if (!event.empty()) std::fprintf(stderr, "apm25sim: t=%.3f s: tcp:%d %s\n", time_s(), options_.serial->port(), event.c_str());
        if (!received.empty()) {
            if (input_pos_ > 65536) {  // a long session: what has been typed is not kept
                options_.input.erase(0, input_pos_);
                input_consumed_ += input_pos_;
                input_pos_ = 0;
            }
            options_.input += received;
            if (input_started_) arm_input();
        }
    }
    return avr_->cycle + kCpuHz / 1000;
}

uint64_t Board::on_uart_input_tick() {
    if (!input_started_) {  // called by the start timer
        start_input();
        return 0;
    }
    if (input_pos_ >= options_.input.size()) return 0;
    // simavr hands the core a received byte one character time after the previous one
    // was read, so over a long burst it falls behind the line by the interrupt's latency
    // and its FIFO fills (a real USART takes a byte every character time whatever the
    // reader does). While simavr says XOFF the next byte waits, instead of being lost
    // inside the simulator; the wait is counted (uart_input_held_chars, --verbose).
    if (!uart_input_held_) avr_raise_irq(uart_input_irq_, (uint8_t)options_.input[input_pos_++]);
    else ++uart_input_held_chars_;
    // One character = 10 bits at the baud rate UBRR0 sets (datasheet 22.3.1).
    const unsigned ubrr = (unsigned)avr_->data[kUbrr0l] | ((unsigned)(avr_->data[kUbrr0h] & 0x0F) << 8);
    const unsigned divisor = (avr_->data[kUcsr0a] & 0x02) ? 8u : 16u;  // U2X0
    const uint64_t cycles_per_char = 10u * (uint64_t)divisor * (ubrr + 1u);
    return avr_->cycle + cycles_per_char;
}

// --- the GPS port (UART1) -----------------------------------------------------------

// simavr's UART1 module ("uart" named '1' in the core's list of I/O modules).
bool Board::init_gps_port() {
    for (avr_io_t* port = avr_->io_port; port != nullptr; port = port->next) {
        if (port->kind == nullptr || std::strcmp(port->kind, "uart") != 0) continue;
        avr_uart_t* uart = reinterpret_cast<avr_uart_t*>(port);  // io is its first member
        if (uart->name == '1') uart1_ = uart;
    }
    avr_uart_t* uart = static_cast<avr_uart_t*>(uart1_);
    if (!uart || uart->ubrrl.reg != kUbrr1l) {
        error_ = "simavr's atmega2560 has no UART1 where this harness expects it";
        return false;
    }
    avr_irq_register_notify(avr_io_getirq(avr_, AVR_IOCTL_UART_GETIRQ('1'), UART_IRQ_OUTPUT), uart1_output_hook, this);
    uart1_input_irq_ = avr_io_getirq(avr_, AVR_IOCTL_UART_GETIRQ('1'), UART_IRQ_INPUT);
    avr_irq_register_notify(avr_io_getirq(avr_, AVR_IOCTL_UART_GETIRQ('1'), UART_IRQ_OUT_XOFF), uart1_xoff_hook, this);
    avr_irq_register_notify(avr_io_getirq(avr_, AVR_IOCTL_UART_GETIRQ('1'), UART_IRQ_OUT_XON), uart1_xon_hook, this);
    ubrr1l_original_ = avr_->io[AVR_DATA_TO_IO(kUbrr1l)].w.c;
    ubrr1l_original_param_ = avr_->io[AVR_DATA_TO_IO(kUbrr1l)].w.param;
    if (ubrr1l_original_) {
        avr_->io[AVR_DATA_TO_IO(kUbrr1l)].w.c = ubrr1l_write_hook;
        avr_->io[AVR_DATA_TO_IO(kUbrr1l)].w.param = this;
    }
    arm_gps_timer();
    return true;
}

// The bit time the firmware set on USART1 (UBRR1, U2X1): its receiver's and transmitter's.
double Board::uart1_bit_s() const {
    const unsigned ubrr = (unsigned)avr_->data[kUbrr1l] | ((unsigned)(avr_->data[kUbrr1h] & 0x0F) << 8);
    return usart_bit_s(kCpuHz, ubrr, (avr_->data[kUcsr1a] & kU2x) != 0);
}

// simavr 1.6 counts 11 bits a character (a parity bit 8N1 does not send): its RX pump
// would lag the GPS line by a tenth. A character is 10 bit times.
void Board::on_ubrr1l_write(uint16_t addr, uint8_t value) {
    ubrr1l_original_(avr_, addr, value, ubrr1l_original_param_);
    avr_uart_t* uart = static_cast<avr_uart_t*>(uart1_);
    const unsigned ubrr = (unsigned)avr_->data[kUbrr1l] | ((unsigned)(avr_->data[kUbrr1h] & 0x0F) << 8);
    uart->cycles_per_byte = (avr_cycle_count_t)10u * ((avr_->data[kUcsr1a] & kU2x) ? 8u : 16u) * (ubrr + 1u);
}

// A byte the firmware writes to UDR1: on the line to the module at the firmware's baud,
// after the one before it (the USART's shift register sends one at a time).
void Board::on_uart1_byte(uint8_t byte) {
    if (!gps_) return;
    UartFrame f;
    f.bit_s = uart1_bit_s();
    f.start_s = std::max(time_s(), uart1_tx_free_s_);
    f.byte = byte;
    uart1_tx_free_s_ = f.end_s();
    ++gps_port_.bytes_from_firmware;
    gps_->line_in(f);
    arm_gps_timer();
}

void Board::arm_gps_timer() {
    if (!gps_) return;
    double next_s = gps_->next_event_s();
    next_s = std::min(next_s, uart1_rx_.next_ready_s());
    if (!uart1_pending_.empty()) next_s = std::min(next_s, uart1_pending_.front().ready_s);
    next_s = std::min(next_s, time_s() + 0.01);
    uint64_t when = (uint64_t)std::ceil(next_s * kCpuHz);
    if (when <= avr_->cycle) when = avr_->cycle + 1;
    if (gps_timer_at_ != 0 && gps_timer_at_ <= when) return;  // armed early enough
    avr_cycle_timer_cancel(avr_, gps_timer, this);
    avr_cycle_timer_register(avr_, when - avr_->cycle, gps_timer, this);
    gps_timer_at_ = when;
}

// The module's line into the firmware's USART1 receiver, decoded at the baud the firmware
// set (UartLine.h): at equal baud the module's bytes, else what a UART makes of them.
// Each character is raised on simavr's UART1 RX at the start of its frame: simavr hands it
// to the core one character time later, when the stop bit is in, as the chip's RXC1.
uint64_t Board::on_gps_tick() {
    gps_timer_at_ = 0;
    const double now_s = time_s();
    gps_->advance_to(now_s);
    UartFrame f;
    const bool receiving = (avr_->data[kUcsr1b] & kRxen) != 0;
    while (gps_->pop_frame(f)) {
        // With RXEN1 off the USART does not look at the line (datasheet 22.8): the frames
        // are lost, and its receiver starts afresh once enabled.
        if (receiving) uart1_rx_.push(f);
        else ++gps_port_.dropped_receiver_off;
    }
    if (!receiving) {
        uart1_rx_.reset();
        uart1_pending_.clear();
    }
    uart1_rx_.set_bit_s(uart1_bit_s());
    uart1_scratch_.clear();
    uart1_rx_.decode(now_s, uart1_scratch_);
    for (const UartChar& c : uart1_scratch_) uart1_pending_.push_back(c);
    while (!uart1_pending_.empty() && uart1_pending_.front().ready_s <= now_s) {
        const UartChar c = uart1_pending_.front();
        if (uart1_held_) {
            ++gps_port_.held_chars;            // simavr's RX FIFO is full: wait a character
            break;
        } else {
            if (!c.framing_ok) ++gps_port_.framing_errors;  // the chip sets FE1 and keeps the byte
            ++gps_port_.bytes_to_firmware;
            avr_raise_irq(uart1_input_irq_, c.byte);
        }
        uart1_pending_.pop_front();
    }
    double next_s = gps_->next_event_s();
    next_s = std::min(next_s, uart1_rx_.next_ready_s());
    if (!uart1_pending_.empty())
        next_s = std::min(next_s, uart1_held_ ? now_s + uart1_bit_s() * 10.0 : uart1_pending_.front().ready_s);
    next_s = std::min(next_s, now_s + 0.01);
    uint64_t next_cycle = (uint64_t)std::ceil(next_s * kCpuHz);
    if (next_cycle <= avr_->cycle) next_cycle = avr_->cycle + 1;
    gps_timer_at_ = next_cycle;
    return next_cycle;
}

// --- receiver (PPM on ICP5) and servo outputs -----------------------------------

// The PPM line is PL1's pin IRQ. simavr connects a timer's capture input to its ICP pin
// only when the core names the pin (avr_timer_t.icp) and the edge-select bit (ices);
// where the ATmega2560 core leaves Timer5's unnamed, the capture IRQ is raised with the
// pin, and simavr's own capture (ICR5 <- TCNT5, ICF5, on the ICES5 edge) does the rest.
bool Board::init_rc() {
    if (!options_.rc) return true;
    avr_timer_t* timer5 = find_timer(avr_, '5');
    if (!timer5) {
        error_ = "simavr's atmega2560 has no Timer5";
        return false;
    }
    if (timer5->ices.reg == 0) {
        error_ = "simavr's atmega2560 Timer5 has no ICES5 bit: its input capture cannot work";
        return false;
    }
    ppm_pin_irq_ = avr_io_getirq(avr_, AVR_IOCTL_IOPORT_GETIRQ('L'), kPpmBit);
    const bool wired = timer5->icp.reg != 0;
    if (!wired) ppm_icp_irq_ = avr_io_getirq(avr_, AVR_IOCTL_TIMER_GETIRQ('5'), TIMER_IRQ_IN_ICP);
    // The encoder's line idles high before the first frame (no edge the firmware could
    // capture: it has not configured Timer5 yet).
    avr_raise_irq(ppm_pin_irq_, 1);
    if (ppm_icp_irq_) avr_raise_irq(ppm_icp_irq_, 1);
    ppm_.reset(new PpmEncoder(*options_.rc));
    schedule_ppm_edge();
    return true;
}

void Board::schedule_ppm_edge() {
    if (ppm_pending_ || !ppm_ || !ppm_->next_edge(ppm_next_)) return;
    ppm_pending_ = true;
    uint64_t when = (uint64_t)std::llround(ppm_next_.t_s * kCpuHz);
    if (when <= avr_->cycle) when = avr_->cycle + 1;
    avr_cycle_timer_register(avr_, when - avr_->cycle, ppm_edge_timer, this);
}

uint64_t Board::on_ppm_edge() {
    ppm_pending_ = false;
    avr_raise_irq(ppm_pin_irq_, ppm_next_.high ? 1 : 0);
    if (ppm_icp_irq_) avr_raise_irq(ppm_icp_irq_, ppm_next_.high ? 1 : 0);
    schedule_ppm_edge();
    return 0;
}

void Board::rc_changed() { schedule_ppm_edge(); }

// simavr's ADC converts the millivolts last raised on the channel's IRQ.
void Board::set_a0_mV(double mV) { set_adc_mV(0, mV); }

void Board::set_adc_mV(int channel, double mV) {
    if (channel < 8)
        avr_raise_irq(avr_io_getirq(avr_, AVR_IOCTL_ADC_GETIRQ, ADC_IRQ_ADC0 + channel),
                      (uint32_t)std::lround(std::max(mV, 0.0)));
    else if (channel < 16)
        adc_high_mV_[channel - 8] = std::max(mV, 0.0);
}

// A read of ADCL after a conversion of ADC8..15 (MUX5 set, single-ended: MUX4:3 clear):
// the result the datasheet gives (26.7: ADC = Vin x 1024 / Vref, at most 1023) from the
// millivolts set_adc_mV() keeps, at the reference REFS1:0 select (AREF, AVCC, 1.1 V,
// 2.56 V), left-adjusted with ADLAR, as simavr's own conversion of ADC0..7 stores it: its
// register pair until the next conversion ends (read_status). Everything else: simavr's.
uint8_t Board::on_adcl_read(uint16_t addr) {
    avr_adc_t* adc = static_cast<avr_adc_t*>(adcl_original_param_);
    const uint8_t admux = avr_->data[kAdmux];
    const bool high = (avr_->data[kAdcsrb] & 0x08u) != 0u && (admux & 0x18u) == 0u;
    if (!high || adc->read_status) return adcl_original_(avr_, addr, adcl_original_param_);
    const uint32_t vref_mV[4] = {avr_->aref, avr_->avcc, 1100u, 2560u};
    const double vref = vref_mV[admux >> 6] ? vref_mV[admux >> 6] : 5000.0;
    const double exact = std::floor(adc_high_mV_[admux & 0x07u] * 1024.0 / vref);
    uint32_t counts = exact > 1023.0 ? 0x3FFu : (uint32_t)exact;
    if (admux & 0x20u) counts <<= 6;  // ADLAR
    avr_->data[kAdcl] = (uint8_t)counts;
    avr_->data[kAdcl + 1] = (uint8_t)(counts >> 8);
    adc->read_status = 1;
    return avr_->data[addr];
}

// Each output's level is the OCnx unit's while TCCRnA's COMnx bits connect it to the pin
// (as the hardware overrides PORT), else the PORT bit when the pin is an output, else
// low. The compare units report through the timer's OUT_COMP IRQs (simavr 1.6 sets bit 8,
// AVR_IOPORT_OUTPUT, on a toggle: the level is bit 0). The level is worked out by the
// chip's rule rather than taken from the pin IRQ's value, so that a PORT bit written on a
// pin the timer owns (no effect on the chip) can never count as an edge; the pin IRQ is
// the cue to look again.
void Board::init_servo_outputs() {
    for (int i = 0; i < kServoOutputs; ++i) {
        const ServoOutputPin& pin = kServoPins[i];
        g_servo_hooks[i] = ServoHook{this, i + 1};
        avr_irq_register_notify(avr_io_getirq(avr_, AVR_IOCTL_TIMER_GETIRQ(pin.timer), TIMER_IRQ_OUT_COMP + pin.compare),
                                servo_compare_hook, &g_servo_hooks[i]);
        avr_irq_register_notify(avr_io_getirq(avr_, AVR_IOCTL_IOPORT_GETIRQ(pin.port), pin.bit), servo_pin_hook, this);
    }
    if (options_.servo_log) std::fputs(ServoPulseLog::header(), options_.servo_log);
}

void Board::on_servo_compare(int output, uint32_t value) {
    servo_oc_level_[output - 1] = (uint8_t)(value & 1);
    on_servo_pin();
}

void Board::on_servo_pin() {
    const double t_s = time_s();
    for (int i = 0; i < kServoOutputs; ++i) {
        const ServoOutputPin& pin = kServoPins[i];
        const uint8_t com = (uint8_t)((avr_->data[pin.tccra] >> (6 - 2 * pin.compare)) & 0x03);
        const bool output = (avr_->data[pin.ddr] >> pin.bit) & 1;
        bool high = false;
        if (output) high = com != 0 ? servo_oc_level_[i] != 0 : ((avr_->data[pin.port_reg] >> pin.bit) & 1) != 0;
        servo_pulses_.level(i + 1, t_s, high);
    }
    write_servo_pulses(false);
}

void Board::write_servo_pulses(bool all) {
    servo_ready_.clear();
    servo_pulses_.take(servo_ready_, all);  // taken also without a log: they would pile up
    if (!options_.servo_log) return;
    for (const ServoPulse& p : servo_ready_) std::fputs(ServoPulseLog::format(p).c_str(), options_.servo_log);
}

void Board::append_sample(const TrajectorySample& sample, double keep_s) {
    std::vector<Trajectory*> trajectories = {&mpu_.trajectory(), &mag_.trajectory()};
    if (gps_) trajectories.push_back(&gps_->trajectory());
    if (baro_) trajectories.push_back(&baro_->trajectory());
    for (Trajectory* t : trajectories) {
        t->append(sample);
        // Trimmed now and then, not at every sample (the erase moves the whole history).
        if (t->size() > 4096 && (*t)[0].t_s < sample.t_s - 2.0 * keep_s) t->drop_before(sample.t_s - keep_s);
    }
}

// --- EEPROM -------------------------------------------------------------------

// simavr's EEPROM module ("eeprom" in the core's list of I/O modules). Its memory is
// reached directly: simavr 1.6's AVR_IOCTL_EEPROM_GET/SET return -1 even when they work
// (and GET does not copy), so their result cannot be trusted.
uint8_t* Board::eeprom_bytes() const {
    for (avr_io_t* port = avr_ ? avr_->io_port : nullptr; port != nullptr; port = port->next) {
        if (port->kind == nullptr || std::strcmp(port->kind, "eeprom") != 0) continue;
        avr_eeprom_t* e = reinterpret_cast<avr_eeprom_t*>(port);  // io is its first member
        return e->eeprom != nullptr && e->size == kEepromSize ? e->eeprom : nullptr;
    }
    return nullptr;
}

// The file's bytes from address 0; beyond its end (or without a file) the EEPROM is
// erased (0xFF), as a new chip. The file is the chip: any byte pattern is accepted,
// a file longer than the chip is refused.
bool Board::load_eeprom() {
    if (options_.eeprom_path.empty() && options_.mission_path.empty()) return true;
    std::vector<uint8_t> bytes(kEepromSize, 0xFF);
    FILE* f = options_.eeprom_path.empty() ? nullptr : std::fopen(options_.eeprom_path.c_str(), "rb");
    if (f) {
        const size_t n = std::fread(bytes.data(), 1, kEepromSize, f);
        const bool longer = std::fgetc(f) != EOF;
        std::fclose(f);
        (void)n;
        if (longer) {
            error_ = "the EEPROM file '" + options_.eeprom_path + "' is longer than the chip's 4096 bytes";
            return false;
        }
    }
    if (!options_.mission_path.empty() && !sim::write_mission_file(options_.mission_path, bytes, error_)) {
        error_ = "--mission: " + error_;
        return false;
    }
    uint8_t* chip = eeprom_bytes();
    if (!chip) {
        error_ = "simavr's atmega2560 has no 4096-byte EEPROM module";
        return false;
    }
    std::memcpy(chip, bytes.data(), kEepromSize);
    return true;
}

bool Board::save_eeprom() {
    if (options_.eeprom_path.empty() || !avr_) return true;
    return write_eeprom(options_.eeprom_path);
}

// Before each instruction: the chip as a run cut at this instant (--seconds) leaves it,
// at each cut time reached (a write holds its byte from its start: on_eecr_write).
void Board::take_eeprom_cuts() {
    const double at_s = options_.eeprom_cuts_from_s + options_.eeprom_cuts_step_s * eeprom_cuts_taken_;
    if (at_s > options_.eeprom_cuts_to_s + 1e-9 || avr_->cycle < (avr_cycle_count_t)std::llround(at_s * kCpuHz))
        return;
    const std::string path = options_.eeprom_path + ".cut" + std::to_string(eeprom_cuts_taken_);
    if (!write_eeprom(path)) std::fprintf(stderr, "apm25sim: cannot write '%s'\n", path.c_str());
    ++eeprom_cuts_taken_;
}

bool Board::write_eeprom(const std::string& path) const {
    const uint8_t* chip = eeprom_bytes();
    if (!chip) return false;
    const std::vector<uint8_t> bytes(chip, chip + kEepromSize);
    // Through a temporary file and a rename: an interrupted write never leaves half a chip.
    const std::string tmp = path + ".tmp";
    FILE* f = std::fopen(tmp.c_str(), "wb");
    if (!f) return false;
    const bool ok = std::fwrite(bytes.data(), 1, kEepromSize, f) == kEepromSize;
    if (std::fclose(f) != 0 || !ok) return false;
    return std::rename(tmp.c_str(), path.c_str()) == 0;
}

// --- profiling ----------------------------------------------------------------

void Board::on_gpior_write(bool end, uint8_t value) {
    if (value == 0 || value > kMaxSectionId) return;
    SectionProfile& s = sections_[value];
    const uint64_t now = avr_->cycle;
    if (!end) {
        if (s.open) ++profile_errors_;
        s.open = true;
        s.started_at = now;
        if (value == 6 && !run_started_) {
            run_started_ = true;
            run_first_start_ = now;
        }
        return;
    }
    if (!s.open) {
        ++profile_errors_;
        return;
    }
    s.open = false;
    const uint64_t cycles = now - s.started_at;
    ++s.count;
    s.total += cycles;
    if (cycles < s.min) s.min = cycles;
    if (cycles > s.max) s.max = cycles;
    if (value == 6) run_last_end_ = now;
}

bool Board::write_profile(const std::string& path) const {
    FILE* f = std::fopen(path.c_str(), "w");
    if (!f) return false;
    std::fprintf(f, "section,count,avg_cycles,min_cycles,max_cycles,total_cycles\n");
    for (int id = 1; id <= kMaxSectionId; ++id) {
        const SectionProfile& s = sections_[id];
        if (s.count == 0) continue;
        std::fprintf(f, "%d,%llu,%llu,%llu,%llu,%llu\n", id, (unsigned long long)s.count,
                     (unsigned long long)(s.total / s.count), (unsigned long long)s.min,
                     (unsigned long long)s.max, (unsigned long long)s.total);
    }
    const unsigned long long window = run_started_ && run_last_end_ > run_first_start_
                                          ? (unsigned long long)(run_last_end_ - run_first_start_)
                                          : 0ull;
    std::fprintf(f, "run,1,%llu,%llu,%llu,%llu\n", window, window, window, window);
    // The stack's high-water mark: the painted bytes above the static data that nothing
    // overwrote (free), the rest of the RAM above it (used by the stack at its deepest).
    unsigned long long free_bytes = 0, used_bytes = 0;
    if (avr_ && static_end_ <= avr_->ramend) {
        uint32_t a = static_end_;
        while (a <= avr_->ramend && avr_->data[a] == profile::kStackPaint) ++a;
        free_bytes = a - static_end_;
        used_bytes = (unsigned long long)avr_->ramend + 1u - a;
    }
    std::fprintf(f, "stack_used,1,%llu,%llu,%llu,%llu\n", used_bytes, used_bytes, used_bytes, used_bytes);
    std::fprintf(f, "stack_free,1,%llu,%llu,%llu,%llu\n", free_bytes, free_bytes, free_bytes, free_bytes);
    return std::fclose(f) == 0;
}

void Board::print_counters(FILE* out) const {
    const Mpu6000Counters& m = mpu_.counters();
    const Hmc5883Counters& h = mag_.counters();
    std::fprintf(out,
                 "# apm25sim: t=%.3f s; MPU6000 transactions=%u bytes=%u writes=%u samples=%u not_read=%u "
                 "absent_bytes=%u reset_bytes=%u asleep_reads=%u ro_writes=%u fast_writes=%u\n",
                 time_s(), m.transactions, m.bytes, m.register_writes, m.samples, m.samples_not_read,
                 m.access_while_absent, m.access_during_reset, m.data_read_while_asleep, m.writes_to_read_only,
                 m.writes_above_1mhz);
    std::fprintf(out,
                 "# apm25sim: HMC5883L transactions=%u written=%u read=%u samples=%u lock_dropped=%u nacked=%u "
                 "ro_writes=%u invalid_reads=%u; bus violations=%u; profile marker errors=%u\n",
                 h.transactions, h.bytes_written, h.bytes_read, h.samples, h.samples_dropped_by_lock,
                 h.nacked_while_absent, h.writes_to_read_only, h.reads_of_invalid_register, bus_violations_,
                 profile_errors_);
    std::fprintf(out, "# apm25sim: UART0 input %llu of %llu bytes typed, %llu character times held by XOFF\n",
                 (unsigned long long)(input_consumed_ + input_pos_),
                 (unsigned long long)(input_consumed_ + options_.input.size()), (unsigned long long)uart_input_held_chars_);
    if (gps_) {
        const UbloxCounters& g = gps_->counters();
        const ubx::StreamParser::Counters& pc = gps_->parser_counters();
        std::fprintf(out,
                     "# apm25sim: GPS baud=%u in=0x%04x out=0x%04x rate_ms=%u epochs=%u ubx_out=%u nmea_out=%u "
                     "tx_dropped=%u bytes_out=%u silenced=%u garbage=%u bytes_in=%u framing_in=%u deaf=%u "
                     "nmea_only_ignored=%u protocol_ignored=%u ubx_in=%u ubx_bad_ck=%u nmea_in=%u nmea_bad_ck=%u "
                     "acks=%u naks=%u polls=%u pubx41=%u pubx40=%u port_changes=%u not_modelled=%u\n",
                     gps_->baud(), gps_->in_proto(), gps_->out_proto(), gps_->meas_rate_ms(), g.epochs,
                     g.ubx_messages_out, g.nmea_sentences_out, g.tx_dropped_messages, g.bytes_out, g.bytes_silenced,
                     g.garbage_bytes, g.bytes_in, g.framing_errors_in, g.ignored_deaf, g.ignored_nmea_only,
                     g.ignored_protocol, pc.ubx_frames, pc.ubx_bad_checksum, pc.nmea_sentences, pc.nmea_bad_checksum,
                     g.acks, g.naks, g.polls, g.pubx41, g.pubx40, g.port_changes, g.not_modelled);
        std::fprintf(out,
                     "# apm25sim: GPS port to_firmware=%u framing=%u receiver_off=%u held_chars=%llu "
                     "from_firmware=%u\n",
                     gps_port_.bytes_to_firmware, gps_port_.framing_errors, gps_port_.dropped_receiver_off,
                     (unsigned long long)gps_port_.held_chars, gps_port_.bytes_from_firmware);
    }
    if (baro_) {
        const Ms5611Counters& b = baro_->counters();
        std::fprintf(out,
                     "# apm25sim: MS5611 transactions=%u bytes=%u resets=%u conversions=%u prom_reads=%u "
                     "adc_reads=%u adc_zero=%u read_converting=%u cmd_converting=%u cmd_resetting=%u unknown=%u "
                     "absent_bytes=%u wrong_mode=%u\n",
                     b.transactions, b.bytes, b.resets, b.conversions, b.prom_reads, b.adc_reads, b.adc_reads_zero,
                     b.reads_during_conversion, b.commands_during_conversion, b.commands_during_reset,
                     b.unknown_commands, b.bytes_while_absent, b.bytes_wrong_spi_mode);
    }
    if (options_.serial)
        std::fprintf(out, "# apm25sim: tcp:%d: %llu TX bytes dropped (client not reading)\n", options_.serial->port(),
                     (unsigned long long)options_.serial->dropped());
    if (ppm_)
        std::fprintf(out, "# apm25sim: PPM frames begun %lu; ICP5 fed %s\n", ppm_->frames(),
                     ppm_icp_irq_ ? "through Timer5's capture IRQ (the core leaves the pin unwired)"
                                  : "through PL1 (the core wires it to Timer5's capture)");
}

}  // namespace sim
