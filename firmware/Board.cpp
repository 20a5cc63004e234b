#include "Board.h"

#include <avr/interrupt.h>
#include <util/atomic.h>

namespace board {

void start_clock() {
    TCCR0A = _BV(WGM01) | _BV(WGM00);
    TCCR0B = _BV(CS01) | _BV(CS00);
    TIMSK0 = _BV(TOIE0);
    sei();
}

void init_pins() {
    // Outputs written high before they are outputs: no low glitch on a chip select.
    PORTA |= _BV(PA5) | _BV(PA4) | _BV(PA3);  // LEDs off
    DDRA |= _BV(PA5) | _BV(PA4) | _BV(PA3);
    PORTB |= _BV(PB0);                          // MPU6000 CS (pin 53) first,
    DDRB |= _BV(PB0);
    PORTG |= _BV(PG1);                          // then the barometer's (pin 40)
    DDRG |= _BV(PG1);
    DDRC &= (uint8_t)~_BV(PC6);                 // HMC5883L DRDY
    DDRE &= (uint8_t)~_BV(PE6);                 // MPU6000 INT
}

void set_leds(bool calibrating, bool running, bool fault) {
    uint8_t on = 0;  // active low: a set bit here drives the LED's pin low
    if (calibrating) on |= _BV(PA5);
    if (running) on |= _BV(PA4);
    if (fault) on |= _BV(PA3);
    PORTA = (uint8_t)((PORTA | (_BV(PA5) | _BV(PA4) | _BV(PA3))) & ~on);
}

// ---------------------------------------------------------------------------
// SPI master, mode 0, MSB first. 8 MHz = fosc/2 (SPI2X) for sensor reads, 1 MHz =
// fosc/16 for the MPU6000's register writes (datasheet limit).
void spi_begin() {
    DDRB |= _BV(PB1) | _BV(PB2);  // SCK, MOSI out; MISO (PB3) in; SS (PB0) already an output
    SPCR = _BV(SPE) | _BV(MSTR) | _BV(SPR0);
}

static void spi_select(void*, bool on, uint32_t clock_hz) {
    if (on) {
        if (clock_hz >= mpu6000::kReadClockHz) {
            SPCR = _BV(SPE) | _BV(MSTR);
            SPSR = _BV(SPI2X);
        } else {
            SPCR = _BV(SPE) | _BV(MSTR) | _BV(SPR0);
            SPSR = 0;
        }
        PORTB &= (uint8_t)~_BV(PB0);  // pin 53 low; pin 40 (barometer) is never touched
    } else {
        PORTB |= _BV(PB0);
    }
}
static uint8_t spi_transfer(void*, uint8_t out) {
    SPDR = out;
    while (!(SPSR & _BV(SPIF))) {}  // a master transfer always completes (16..128 cycles)
    return SPDR;
}
static void wait_ms(void*, uint16_t ms) { delay(ms); }

const mpu6000::SpiDevice kSpi = {nullptr, spi_select, spi_transfer, wait_ms};

// ---------------------------------------------------------------------------
// I2C master on the TWI at register level, interrupt-driven like the Arduino Wire
// (simavr 1.6 completes an SLA+R only through the interrupt), in ~1/4 of Wire's flash
// (Wire, its Stream/Print vtable and digitalWrite cost ~2.4 KB). One transaction at a
// time: START, SLA, the bytes, STOP. The caller waits with a 3 ms bound; on a timeout
// the TWI is reset and i2c_timed_out() says so once.
static constexpr uint32_t kI2cTimeoutUs = 3000;  // any bus call returns within ~3 ms
static constexpr uint8_t kTwiGo = _BV(TWINT) | _BV(TWEN) | _BV(TWIE);
static constexpr uint8_t kTwiStop = _BV(TWINT) | _BV(TWEN) | _BV(TWSTO);

static uint8_t twi_sla;                // address byte with R/W
static uint8_t* twi_buf;               // bytes to send / received
static volatile uint8_t twi_len, twi_index;
static volatile int8_t twi_result;     // 0 running, 1 done, -1 failed
static bool twi_timeout_flag = false;

static void twi_enable() {
    TWSR = 0;                                                    // prescaler 1
    TWBR = (uint8_t)((F_CPU / kI2cClockHz - 16u) / 2u);         // 12: 400 kHz
    TWCR = _BV(TWEN);
}

void wire_begin() {
    PORTD |= _BV(PD0) | _BV(PD1);  // internal pull-ups, as Wire.begin() sets them
    twi_enable();
}

bool i2c_timed_out() {
    const bool t = twi_timeout_flag;
    twi_timeout_flag = false;
    return t;
}

ISR(TWI_vect) {
    const uint8_t st = TWSR & 0xF8u;
    const uint8_t i = twi_index;
    switch (st) {
        case 0x08:  // START
        case 0x10:  // repeated START
            TWDR = twi_sla;
            TWCR = kTwiGo;
            return;
        case 0x18:  // SLA+W acknowledged
        case 0x28:  // data byte acknowledged
            if (i < twi_len) {
                TWDR = twi_buf[i];
                twi_index = (uint8_t)(i + 1u);
                TWCR = kTwiGo;
                return;
            }
            break;  // all sent: STOP, done
        case 0x50:  // byte received, ACK returned
            twi_buf[i] = TWDR;
            twi_index = (uint8_t)(i + 1u);
            // fall through: ask for the next byte
        case 0x40:  // SLA+R acknowledged
            // ACK every byte but the last.
            TWCR = (uint8_t)(kTwiGo | ((uint8_t)(twi_index + 1u) < twi_len ? _BV(TWEA) : 0));
            return;
        case 0x58:  // last byte received, NACK returned
            twi_buf[i] = TWDR;
            twi_index = (uint8_t)(i + 1u);
            break;
        default:    // NACK on address or data, arbitration lost, bus error
            TWCR = kTwiStop;
            twi_result = -1;
            return;
    }
    TWCR = kTwiStop;
    twi_result = 1;
}

// One transaction, bounded: true when every byte went (or came) with an ACK.
static bool twi_transfer(uint8_t addr7, bool read, uint8_t* data, uint8_t len) {
    twi_sla = (uint8_t)((uint8_t)(addr7 << 1) | (read ? 1u : 0u));
    twi_buf = data;
    twi_len = len;
    twi_index = 0;
    twi_result = 0;
    const uint32_t start = micros();
    TWCR = (uint8_t)(kTwiGo | _BV(TWSTA));
    while (twi_result == 0 || (TWCR & _BV(TWSTO))) {  // done, and the STOP is out
        if (micros() - start > kI2cTimeoutUs) {
            TWCR = 0;  // release the bus and reset the TWI
            twi_enable();
            twi_timeout_flag = true;
            return false;
        }
    }
    return twi_result > 0;
}

static bool i2c_write_reg(void*, uint8_t addr7, uint8_t reg, uint8_t value) {
    uint8_t b[2] = {reg, value};
    return twi_transfer(addr7, false, b, 2);
}

static bool i2c_read_regs(void*, uint8_t addr7, uint8_t reg, uint8_t* data, uint8_t len) {
    return twi_transfer(addr7, false, &reg, 1) && twi_transfer(addr7, true, data, len);
}

const hmc5883::I2cBus kI2c = {nullptr, i2c_write_reg, i2c_read_regs, wait_ms};

void i2c_recover() {
    TWCR = 0;  // the pins back to the port
    DDRD &= (uint8_t)~(_BV(PD0) | _BV(PD1));
    PORTD |= _BV(PD0) | _BV(PD1);
    delayMicroseconds(5);
    for (uint8_t i = 0; i < 16 && sda_low(); ++i) {
        PORTD &= (uint8_t)~_BV(PD0);  // open drain: drive SCL low, release to the pull-up
        DDRD |= _BV(PD0);
        delayMicroseconds(5);
        DDRD &= (uint8_t)~_BV(PD0);
        PORTD |= _BV(PD0);
        delayMicroseconds(5);
    }
    // STOP: SDA rises while SCL is high.
    PORTD &= (uint8_t)~_BV(PD1);
    DDRD |= _BV(PD1);
    delayMicroseconds(5);
    DDRD &= (uint8_t)~_BV(PD1);
    PORTD |= _BV(PD1);
    delayMicroseconds(5);
    wire_begin();
}

// ---------------------------------------------------------------------------
// USART0. Indices are uint8_t: a 256-byte ring wraps by itself, and a one-byte index
// is read and written atomically by the loop and the interrupt.
static char tx_ring[256];
static volatile uint8_t tx_head = 0, tx_tail = 0;  // head: next write (loop), tail: next send (ISR)
static constexpr uint8_t kRxMask = 31;
static char rx_ring[kRxMask + 1];
static volatile uint8_t rx_head = 0, rx_tail = 0;

void serial_begin() {
    UCSR0A = _BV(U2X0);
    UBRR0 = (uint16_t)((F_CPU / 4u / 115200u - 1u) / 2u);  // 16: 115200 at 16 MHz (-0.8 %)
    UCSR0C = _BV(UCSZ01) | _BV(UCSZ00);                    // 8N1
    UCSR0B = _BV(RXEN0) | _BV(TXEN0) | _BV(RXCIE0);
}

ISR(USART0_UDRE_vect) {
    const uint8_t t = tx_tail;
    if (t == tx_head) {
        UCSR0B &= (uint8_t)~_BV(UDRIE0);
        return;
    }
    UDR0 = (uint8_t)tx_ring[t];
    tx_tail = (uint8_t)(t + 1u);
}

ISR(USART0_RX_vect) {
    const uint8_t c = UDR0;
    const uint8_t h = rx_head, next = (uint8_t)((h + 1u) & kRxMask);
    if (next != rx_tail) {  // full: the byte is lost (the console says the line is garbage)
        rx_ring[h] = (char)c;
        rx_head = next;
    }
}

static void ring_put(char c) {
    const uint8_t h = tx_head, next = (uint8_t)(h + 1u);
    while (next == tx_tail) {  // full: wait for the UART (interrupts on: the ISR drains)
        UCSR0B |= _BV(UDRIE0);
    }
    tx_ring[h] = c;
    __asm__ __volatile__("" ::: "memory");  // the byte is in the ring before the ISR may send it
    tx_head = next;
}

static inline void tx_kick() { UCSR0B |= _BV(UDRIE0); }

void serial_drain() {
    tx_kick();
    while (tx_tail != tx_head) {}
}

void serial_write(const char* data, uint8_t len) {
    for (uint8_t i = 0; i < len; ++i) ring_put(data[i]);
    tx_kick();
}

int16_t serial_read() {
    const uint8_t t = rx_tail;
    if (t == rx_head) return -1;
    const uint8_t c = (uint8_t)rx_ring[t];
    rx_tail = (uint8_t)((t + 1u) & kRxMask);
    return c;
}

static void sink_write(void*, const char* data, uint8_t len) { serial_write(data, len); }
const text::Sink kSerialSink = {nullptr, sink_write};

}  // namespace board
