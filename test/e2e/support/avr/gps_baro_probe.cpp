// SPDX-License-Identifier: GPL-3.0-or-later
// A tiny AVR program that talks to apm25sim's GPS on UART1 and MS5611 on SPI as a driver
// would, and prints what it got on UART0 (test/e2e/gps_baro_models.py builds and runs it).
// Not a driver: just enough to show the models work through simavr's USART1, the SPI
// bus and the chip selects, with the board's timing.
//
//   prom W0 .. W7            the MS5611's PROM words (hex)
//   early D                  ADC read 5 ms into a 9.04 ms conversion (0 expected)
//   d1 D1 d2 D2              a pressure and a temperature conversion, waited out
//   mismatch bytes N good G  UART1 at 38400 against the module's 9600 for 1.5 s: bytes
//                            received, and whole NMEA sentences with a valid checksum
//   nmea9600 rmc R bad B     at 9600 for 2.5 s: RMC sentences, sentences with a bad checksum
//   ubx acks A naks K posllh P velned V sol S bad B dollars D step T
//                            after $PUBX,41 and at 38400, CFG-MSG x5 and CFG-RATE 200 ms,
//                            3 s of what came: ACKs, NAKs, NAV messages, bad checksums,
//                            '$' seen, the last iTOW step (ms)
//   pos LAT LON HMSL         the last NAV-POSLLH (1e-7 deg, mm)
//   done
#include <Arduino.h>
#include <SPI.h>

static const uint8_t kMpuCs = 53, kBaroCs = 40;

static uint32_t baro(uint8_t cmd, uint8_t nread) {
    SPI.beginTransaction(SPISettings(8000000, MSBFIRST, SPI_MODE0));
    digitalWrite(kBaroCs, LOW);
    SPI.transfer(cmd);
    uint32_t v = 0;
    for (uint8_t i = 0; i < nread; ++i) v = (v << 8) | SPI.transfer(0);
    digitalWrite(kBaroCs, HIGH);
    SPI.endTransaction();
    return v;
}

// NMEA sentences read for `ms`: valid ones counted, RMCs counted.
static void read_nmea(uint32_t ms, uint16_t& bytes, uint16_t& good, uint16_t& bad, uint16_t& rmc) {
    char line[100];
    uint8_t n = 0;
    bool in = false;
    const uint32_t start = millis();
    while (millis() - start < ms) {
        if (!Serial1.available()) continue;
        const char c = (char)Serial1.read();
        ++bytes;
        if (c == '$') {
            in = true;
            n = 0;
            continue;
        }
        if (!in) continue;
        if (c == '\r' || c == '\n') {
            in = false;
            line[n] = 0;
            char* star = strchr(line, '*');
            if (!star) {
                ++bad;
                continue;
            }
            uint8_t x = 0;
            for (char* p = line; p < star; ++p) x ^= (uint8_t)*p;
            if (strtoul(star + 1, nullptr, 16) == x) {
                ++good;
                if (strncmp(line, "GPRMC", 5) == 0) ++rmc;
            } else {
                ++bad;
            }
            continue;
        }
        if (n < sizeof line - 1) line[n++] = c;
        else in = false;
    }
}

static void send_ubx(uint8_t cls, uint8_t id, const uint8_t* payload, uint8_t len) {
    uint8_t a = 0, b = 0;
    const uint8_t head[4] = {cls, id, len, 0};
    Serial1.write(0xB5);
    Serial1.write(0x62);
    for (uint8_t i = 0; i < 4; ++i) {
        Serial1.write(head[i]);
        a += head[i];
        b += a;
    }
    for (uint8_t i = 0; i < len; ++i) {
        Serial1.write(payload[i]);
        a += payload[i];
        b += a;
    }
    Serial1.write(a);
    Serial1.write(b);
}

void setup() {
    Serial.begin(115200);
    // Each chip select high before it becomes an output (APM25.md: 53 first, then 40).
    digitalWrite(kMpuCs, HIGH);
    pinMode(kMpuCs, OUTPUT);
    digitalWrite(kBaroCs, HIGH);
    pinMode(kBaroCs, OUTPUT);
    SPI.begin();

    // --- the MS5611 ---
    baro(0x1E, 0);
    delay(3);
    Serial.print(F("prom"));
    for (uint8_t w = 0; w < 8; ++w) {
        Serial.print(' ');
        Serial.print((uint16_t)baro((uint8_t)(0xA0 + 2 * w), 2), HEX);
    }
    Serial.println();
    baro(0x48, 0);
    delay(5);
    Serial.print(F("early "));
    Serial.println(baro(0x00, 3));
    delay(10);
    baro(0x48, 0);
    delay(10);
    const uint32_t d1 = baro(0x00, 3);
    baro(0x58, 0);
    delay(10);
    const uint32_t d2 = baro(0x00, 3);
    Serial.print(F("d1 "));
    Serial.print(d1);
    Serial.print(F(" d2 "));
    Serial.println(d2);

    // --- the GPS: at the wrong baud, then at its factory 9600 ---
    uint16_t bytes = 0, good = 0, bad = 0, rmc = 0;
    Serial1.begin(38400);
    read_nmea(1500, bytes, good, bad, rmc);
    Serial.print(F("mismatch bytes "));
    Serial.print(bytes);
    Serial.print(F(" good "));
    Serial.println(good);
    Serial1.begin(9600);
    bytes = good = bad = rmc = 0;
    read_nmea(2500, bytes, good, bad, rmc);
    Serial.print(F("nmea9600 rmc "));
    Serial.print(rmc);
    Serial.print(F(" bad "));
    Serial.println(bad);

    // --- to UBX at 38400 as ArduPilot did on APM2 ---
    Serial1.print(F("$PUBX,41,1,0003,0001,38400,0*26\r\n"));
    Serial1.flush();
    delay(20);
    Serial1.begin(38400);
    const uint8_t ids[5] = {0x02, 0x03, 0x04, 0x06, 0x12};
    for (uint8_t i = 0; i < 5; ++i) {
        const uint8_t msg[3] = {0x01, ids[i], 1};
        send_ubx(0x06, 0x01, msg, 3);
    }
    const uint8_t rate[6] = {200, 0, 1, 0, 1, 0};
    send_ubx(0x06, 0x08, rate, 6);

    uint16_t acks = 0, naks = 0, posllh = 0, velned = 0, sol = 0, badck = 0, dollars = 0;
    uint32_t last_itow = 0, step = 0;
    int32_t lat = 0, lon = 0, hmsl = 0;
    uint8_t frame[64];
    uint8_t state = 0;
    uint16_t len = 0, got = 0;
    const uint32_t start = millis();
    while (millis() - start < 3000) {
        if (!Serial1.available()) continue;
        const uint8_t c = (uint8_t)Serial1.read();
        if (c == '$') ++dollars;
        switch (state) {
        case 0:
            state = c == 0xB5 ? 1 : 0;
            break;
        case 1:
            state = c == 0x62 ? 2 : (c == 0xB5 ? 1 : 0);
            got = 0;
            break;
        default:
            if (got < sizeof frame) frame[got] = c;
            ++got;
            if (got == 4) len = (uint16_t)(frame[2] | (frame[3] << 8));
            if (got >= 4 && got == 4u + len + 2u) {
                state = 0;
                if (len + 6u > sizeof frame) break;
                uint8_t a = 0, b = 0;
                for (uint16_t i = 0; i < 4u + len; ++i) {
                    a += frame[i];
                    b += a;
                }
                if (a != frame[4 + len] || b != frame[5 + len]) {
                    ++badck;
                    break;
                }
                const uint8_t* p = frame + 4;
                if (frame[0] == 0x05) (frame[1] == 0x01 ? acks : naks)++;
                if (frame[0] == 0x01 && frame[1] == 0x06) ++sol;
                if (frame[0] == 0x01 && frame[1] == 0x12) ++velned;
                if (frame[0] == 0x01 && frame[1] == 0x02) {
                    ++posllh;
                    uint32_t itow;
                    memcpy(&itow, p, 4);
                    if (last_itow) step = itow - last_itow;
                    last_itow = itow;
                    memcpy(&lon, p + 4, 4);
                    memcpy(&lat, p + 8, 4);
                    memcpy(&hmsl, p + 16, 4);
                }
            }
            break;
        }
    }
    Serial.print(F("ubx acks "));
    Serial.print(acks);
    Serial.print(F(" naks "));
    Serial.print(naks);
    Serial.print(F(" posllh "));
    Serial.print(posllh);
    Serial.print(F(" velned "));
    Serial.print(velned);
    Serial.print(F(" sol "));
    Serial.print(sol);
    Serial.print(F(" bad "));
    Serial.print(badck);
    Serial.print(F(" dollars "));
    Serial.print(dollars);
    Serial.print(F(" step "));
    Serial.println(step);
    Serial.print(F("pos "));
    Serial.print(lat);
    Serial.print(' ');
    Serial.print(lon);
    Serial.print(' ');
    Serial.println(hmsl);
    Serial.println(F("done"));
}

void loop() {}
