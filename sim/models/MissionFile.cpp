// SPDX-License-Identifier: GPL-3.0-or-later
#include "MissionFile.h"

#include <fstream>
#include <sstream>

#include "MissionProtocol.h"
#include "MissionStore.h"

namespace sim {

namespace {

uint8_t read_byte(void* ctx, uint16_t address) { return (*static_cast<std::vector<uint8_t>*>(ctx))[address]; }
void write_byte(void* ctx, uint16_t address, uint8_t v) { (*static_cast<std::vector<uint8_t>*>(ctx))[address] = v; }

}  // namespace

bool write_mission_text(const std::string& text, std::vector<uint8_t>& eeprom, std::string& error) {
    if (eeprom.size() != mission::kEepromSize) {
        error = "the EEPROM image is not 4096 bytes";
        return false;
    }
    std::istringstream in(text);
    std::string line;
    if (!std::getline(in, line) || line.compare(0, 11, "QGC WPL 110") != 0) {
        error = "not a QGC WPL 110 file (its first line)";
        return false;
    }
    std::vector<mission::Command> commands;
    int line_no = 1;
    int expect_seq = 0;
    while (std::getline(in, line)) {
        ++line_no;
        if (line.find_first_not_of(" \t\r") == std::string::npos) continue;
        std::istringstream f(line);
        int seq, current, frame, command, autocontinue;
        double p[4], lat, lon, alt;
        if (!(f >> seq >> current >> frame >> command >> p[0] >> p[1] >> p[2] >> p[3] >> lat >> lon >> alt >>
              autocontinue)) {
            error = "line " + std::to_string(line_no) + ": not 12 numbers";
            return false;
        }
        if (seq != expect_seq++) {
            error = "line " + std::to_string(line_no) + ": seq " + std::to_string(seq) + " out of order";
            return false;
        }
        if (seq == 0) continue;  // home: the board's own
        mission::Item item{};
        item.seq = (uint16_t)seq;
        item.command = (uint16_t)command;
        item.frame = (uint8_t)frame;
        item.current = (uint8_t)current;
        item.autocontinue = (uint8_t)autocontinue;
        item.param1 = (float)p[0];
        item.param2 = (float)p[1];
        item.param3 = (float)p[2];
        item.param4 = (float)p[3];
        // Degrees as doubles to 1e-7 (e7_from_degrees' float loses ~1 m of longitude).
        item.x = (int32_t)(lat * 1e7 + (lat >= 0 ? 0.5 : -0.5));
        item.y = (int32_t)(lon * 1e7 + (lon >= 0 ? 0.5 : -0.5));
        item.z = (float)alt;
        item.int_form = true;
        mission::Command c;
        mission::Result why;
        if (!mission::from_item(item, c, why)) {
            error = "line " + std::to_string(line_no) + ": command " + std::to_string(command) + " frame " +
                    std::to_string(frame) + " refused (MAV_MISSION_RESULT " + std::to_string((int)why) + ")";
            return false;
        }
        commands.push_back(c);
    }
    if (commands.size() > mission::kMaxCommands) {
        error = std::to_string(commands.size()) + " commands: the store holds " + std::to_string(mission::kMaxCommands);
        return false;
    }
    mission::MissionStore store(mission::Eeprom{&eeprom, read_byte, write_byte});
    store.load();
    store.begin_upload();
    for (size_t i = 0; i < commands.size(); ++i) store.write((uint8_t)i, commands[i]);
    store.commit((uint8_t)commands.size());
    return true;
}

bool write_mission_file(const std::string& path, std::vector<uint8_t>& eeprom, std::string& error) {
    std::ifstream f(path);
    if (!f) {
        error = "cannot read '" + path + "'";
        return false;
    }
    std::stringstream text;
    text << f.rdbuf();
    return write_mission_text(text.str(), eeprom, error);
}

}  // namespace sim
