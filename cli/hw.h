// The `hw` verb: a device, real or emulated, through the same servo_tick
// and safety layer: list, probe, record, run, calibrate, motor-test.
// docs/hardware.md is the guide; docs/cli.md the reference.
#ifndef VMHAPTICS_CLI_HW_H_
#define VMHAPTICS_CLI_HW_H_

#include <CLI/CLI.hpp>

namespace vmh::cli {

void register_hw(CLI::App* app);

// the sub-verbs, each in its own file
void register_hw_run(CLI::App* hw);
void register_hw_calibrate(CLI::App* hw);
// hw decode / hw encode: the FireWire Omni's packets by hand (hw_packet.cc)
void register_hw_packet(CLI::App* hw);

}  // namespace vmh::cli

#endif  // VMHAPTICS_CLI_HW_H_
