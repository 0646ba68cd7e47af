// vmhaptics: one command line for the testbed. Each verb prints one JSON
// object on stdout (or writes CSV files); errors are one line on stderr.
//
// Verbs: kin (kinematics of the Omni), ctl (one controller tick), run
// (closed-loop simulation of the thesis cases), study (numerical studies),
// params (the table of case parameters, docs/parameters.md), hw (a device,
// real or emulated: docs/hardware.md), compare (device recordings against
// the project's kinematics and the MJCF Omni) and identify (the Omni model
// fitted to recordings): docs/bringup.md; render (PNG images of a case at
// given times, when built with the viz library).
//
// Exit codes: 0 success, 2 bad usage or bad input (a device that cannot be
// opened included), 1 any other failure (a run whose physics went
// non-finite, a MuJoCo error), 128 + n when signal n (SIGINT, SIGTERM)
// stopped an hw session (its trace is kept, zero torque sent) or a run
// (its complete output sets kept, the others removed).
//
// MuJoCo's own handlers are replaced first of all (sim/mujoco_messages.h):
// its warnings are counted and printed on stderr, one line per kind, just
// before the program ends (before the error line, if any); nothing reaches
// stdout or MUJOCO_LOG.TXT.
#include <CLI/CLI.hpp>
#include <exception>
#include <iostream>

#include "cli/args.h"
#include "cli/hw.h"
#include "cli/kin.h"
#include "hw/backends.h"
#include "runtime/backend_registry.h"
#include "runtime/session.h"
#ifdef VMH_HAVE_SIM
#include "cli/compare.h"
#include "cli/ctl.h"
#include "cli/params.h"
#include "cli/run.h"
#include "cli/study.h"
#include "sim/emulator_backend.h"
#include "sim/mujoco_messages.h"
#endif

namespace vmh::cli {
#ifdef VMH_HAVE_SIM
// cli/identify.cc: fit the Omni model to recordings
void register_identify(CLI::App* app);
// cli/report.cc: the HTML report of the cases and the studies
void register_report(CLI::App* app);
#ifdef VMH_HAVE_VIZ
// cli/render.cc: headless PNG renders of a case
void register_render(CLI::App* app);
// cli/view.cc: the interactive viewer
void register_view(CLI::App* app);
#endif
#endif
}  // namespace vmh::cli

namespace {

// the first line of a message; the error contract is one line on stderr
std::string first_line(const std::string& s) {
  return s.substr(0, s.find('\n'));
}

// CLI11 reports a misspelt verb only as "A subcommand is required"; walk the
// verbs given and name the first unknown one, with the choices
void check_verbs(CLI::App* app, int argc, char** argv) {
  std::string path = "vmhaptics";
  for (int i = 1; i < argc && argv[i][0] != '-'; ++i) {
    const auto subs = app->get_subcommands([](CLI::App*) { return true; });
    if (subs.empty()) break;  // the verb's own positional arguments
    CLI::App* next = nullptr;
    std::string names;
    for (CLI::App* s : subs) {
      if (s->get_name() == argv[i]) next = s;
      names += (names.empty() ? "" : ", ") + s->get_name();
    }
    if (next == nullptr) {
      throw vmh::cli::UsageError("unknown verb '" + std::string(argv[i]) +
                                 "' for '" + path +
                                 "' (expected one of: " + names + ")");
    }
    path += " " + next->get_name();
    app = next;
  }
  // An option the verb does not have is named before CLI11 parses: CLI11
  // checks required options first, so `kin fk --qq 0,...` would say only
  // "--q is required" and hide the typo.
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "--") break;  // the rest are positional
    if (arg.size() < 3 || arg.compare(0, 2, "--") != 0) continue;
    const std::string name = arg.substr(0, arg.find('='));
    if (name == "--help" || name == "--help-all" || name == "--version") continue;
    bool known = false;
    for (const CLI::App* a = app; a != nullptr && !known; a = a->get_parent()) {
      known = a->get_option_no_throw(name) != nullptr;
    }
    if (!known) {
      throw vmh::cli::UsageError("'" + path + "' has no option " + name +
                                 " (see " + path + " --help)");
    }
  }
}

// MuJoCo's warnings of the whole run, one line per kind, on stderr
void print_mujoco_warnings() {
#ifdef VMH_HAVE_SIM
  for (const std::string& line :
       vmh::sim::mujoco_warning_lines(vmh::sim::mujoco_warnings_so_far())) {
    std::cerr << "vmhaptics: warning: " << line << '\n';
  }
#endif
}

// control characters (an ANSI escape in an argument the message quotes) as
// \xNN, so that an error line cannot drive the terminal
std::string escape_controls(const std::string& s) {
  std::string out;
  for (const char ch : s) {
    const auto c = static_cast<unsigned char>(ch);
    if (c < 0x20 || c == 0x7f) {
      static const char kHex[] = "0123456789abcdef";
      out += "\\x";
      out += kHex[c >> 4];
      out += kHex[c & 0xf];
    } else {
      out += ch;
    }
  }
  return out;
}

// the one error line, after the warnings
int fail(int code, const std::string& message, const char* prefix = "error: ") {
  print_mujoco_warnings();
  std::cerr << "vmhaptics: " << prefix << escape_controls(first_line(message))
            << '\n';
  return code;
}

}  // namespace

int main(int argc, char** argv) {
  // the device backends, before the verbs that offer their options
  vmh::runtime::BackendRegistry& backends = vmh::runtime::BackendRegistry::global();
  vmh::hw::register_backends(&backends);
#ifdef VMH_HAVE_SIM
  vmh::sim::install_mujoco_handlers();
  vmh::sim::register_backends(&backends);
#endif
  CLI::App app{
      "vmhaptics: virtual-mechanism control of under-actuated haptic devices "
      "(PHANTOM Omni), after Wickham 2010 and Beckman & Luecke 2008"};
  app.set_version_flag("--version", std::string(VMH_VERSION));
  app.require_subcommand(1);
  vmh::cli::register_kin(&app);
#ifdef VMH_HAVE_SIM
  vmh::cli::register_ctl(&app);
  vmh::cli::register_run(&app);
  vmh::cli::register_study(&app);
  vmh::cli::register_params(&app);
#endif
  vmh::cli::register_hw(&app);
#ifdef VMH_HAVE_SIM
  vmh::cli::register_compare(&app);
  vmh::cli::register_identify(&app);
  vmh::cli::register_report(&app);
#ifdef VMH_HAVE_VIZ
  vmh::cli::register_render(&app);
  vmh::cli::register_view(&app);
#endif
#endif

  // CLI11 reads an empty value of a numeric option as 0: refuse it instead
  vmh::cli::refuse_empty_numbers(&app);

  try {
    check_verbs(&app, argc, argv);
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForVersion& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    return fail(2, e.what());
  } catch (const vmh::cli::UsageError& e) {
    return fail(2, e.what());
  } catch (const vmh::runtime::RequestError& e) {
    return fail(2, e.what());
  } catch (const vmh::DeviceOpenError& e) {
    return fail(2, e.what());
  } catch (const vmh::runtime::SignalStop& e) {
    return fail(128 + e.signal, e.what(), "");
  } catch (const std::exception& e) {
    return fail(1, e.what());
  }
  print_mujoco_warnings();
  return 0;
}
