#include "hw/replay/recording.h"

#include <sys/stat.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>

#include "controller/device_frame.h"
#include "output/output_file.h"
#include "runtime/recording_reader.h"

namespace vmh::hw::replay {
namespace {

namespace fs = std::filesystem;

constexpr const char* kXyz[] = {"x", "y", "z"};

std::string errno_text(int e) { return std::strerror(e); }

// The columns the reader takes and where they are in the header.
struct Layout {
  std::size_t t = 0;
  std::array<std::size_t, 6> q{};
  std::size_t read_error = SIZE_MAX;
  std::size_t buttons = SIZE_MAX, docked = SIZE_MAX;
  std::array<std::size_t, 12> transform{};
  std::array<std::size_t, 3> velocity{};
  std::array<std::size_t, 36> jacobian{};
  std::array<std::size_t, 3> enc{}, pot{};
};

// A group of columns that are there together or not at all: true with
// their indices when all are, false when none is, a RecordingError naming
// the first one missing otherwise.
template <std::size_t N>
bool group(const runtime::TraceReader& t, const std::vector<std::string>& names,
           const std::string& what, std::array<std::size_t, N>* at) {
  std::size_t found = 0;
  std::string have, lack;
  for (std::size_t i = 0; i < N; ++i) {
    (*at)[i] = t.find(names[i]);
    if ((*at)[i] != runtime::TraceReader::npos) {
      ++found;
      if (have.empty()) have = names[i];
    } else if (lack.empty()) {
      lack = names[i];
    }
  }
  if (found == 0) return false;
  if (found < N) {
    throw RecordingError(t.path() + ": column '" + lack + "' is missing (" +
                         have + " is there: " + what +
                         " needs all its columns)");
  }
  return true;
}

std::vector<std::string> names(const std::string& prefix, const char* const* parts,
                               int n, const std::string& suffix) {
  std::vector<std::string> v;
  for (int i = 0; i < n; ++i) v.push_back(prefix + parts[i] + suffix);
  return v;
}

// meta.json, optional for a replay: what it says of the recorded device
// and the session's nominal period, once it has passed the schema
void read_meta(const std::string& path, const RecordingLimits& limits,
               Recording* rec) {
  bool missing = false;
  const runtime::RecordingMeta m = runtime::read_recording_meta(path, limits, &missing);
  if (missing) return;
  rec->has_meta = true;
  rec->recorded = m.device;
  rec->nominal_period_s = m.nominal_period_s;
}

}  // namespace

bool parse_device_error(const std::string& name, DeviceError* e) {
  for (DeviceError d : {DeviceError::kOk, DeviceError::kNotConnected,
                        DeviceError::kIo, DeviceError::kTimeout,
                        DeviceError::kSensorFault, DeviceError::kInvalidCommand}) {
    if (name == device_error_name(d)) {
      *e = d;
      return true;
    }
  }
  return false;
}

double Recording::last_hold_s() const {
  if (nominal_period_s > 0.0) return nominal_period_s;
  if (rows() >= 2) return time_s[rows() - 1] - time_s[rows() - 2];
  return 1e-3;
}

std::size_t Recording::row_at(double t_s) const noexcept {
  if (time_s.empty()) return 0;
  const double tol = 1e-8 * (1.0 + std::fabs(t_s));
  const auto it = std::upper_bound(time_s.begin(), time_s.end(), t_s + tol);
  if (it == time_s.begin()) return 0;
  return static_cast<std::size_t>(it - time_s.begin()) - 1;
}

DeviceError Recording::state_of(std::size_t i, DeviceState* st) const noexcept {
  if (i >= rows()) {
    st->present = 0;
    return DeviceError::kNotConnected;
  }
  if (read_error[i] != DeviceError::kOk) {
    st->present = 0;
    return read_error[i];
  }
  st->present = kStateJoints | present;
  st->q_device_rad = q_device_rad[i];
  st->rehomed = false;
  if (present & kStateButtons) st->buttons = buttons[i];
  if (present & kStateInkwell) st->docked = docked[i] != 0;
  if (present & kStateTransform) {
    const auto& m = transform[i];
    st->transform_mm.setIdentity();
    for (int r = 0; r < 3; ++r) {
      st->transform_mm(r, 3) = m[static_cast<std::size_t>(r)];
      for (int c = 0; c < 3; ++c) {
        st->transform_mm(r, c) = m[static_cast<std::size_t>(3 + 3 * r + c)];
      }
    }
  }
  if (present & kStateVelocity) {
    for (int k = 0; k < 3; ++k) {
      st->velocity_mm_s[k] = velocity_mm_s[i][static_cast<std::size_t>(k)];
    }
  }
  if (present & kStateJacobian) {
    for (int r = 0; r < 6; ++r) {
      for (int c = 0; c < 6; ++c) {
        st->jacobian(r, c) = jacobian[i][static_cast<std::size_t>(6 * r + c)];
      }
    }
  }
  if (present & kStateEncoders) st->encoder_counts = encoders[i];
  if (present & kStatePots) st->gimbal_pots = pots[i];
  return DeviceError::kOk;
}

namespace {

// The current row's integers in three columns, each within int32's range.
std::array<std::int32_t, 3> int32_cells(
    const runtime::TraceReader& p, const std::array<std::size_t, 3>& cols) {
  constexpr double kI32Lo = -2147483648.0, kI32Hi = 2147483647.0;
  std::array<std::int32_t, 3> e{};
  for (std::size_t k = 0; k < 3; ++k) {
    e[k] = static_cast<std::int32_t>(p.integer(cols[k], kI32Lo, kI32Hi));
  }
  return e;
}

// The recording folder: given, there, a folder and not a file, with a
// trace.csv in it; rec's folder (absolute where it can be) and trace file.
void check_folder(const std::string& folder, Recording* rec) {
  if (folder.empty()) {
    throw RecordingError("replay: no recording folder given (replay:DIR, DIR "
                         "written by `vmhaptics hw record --out DIR`)");
  }
  struct stat st {};
  if (::stat(folder.c_str(), &st) != 0) {
    throw RecordingError("replay: recording folder '" + folder + "': " +
                         (errno == ENOENT ? std::string("no such folder")
                                          : errno_text(errno)));
  }
  if (!S_ISDIR(st.st_mode)) {
    throw RecordingError("replay: '" + folder + "' is " +
                         (S_ISREG(st.st_mode) ? std::string("a file")
                                              : output::file_kind(st.st_mode)) +
                         ", not a folder; give the folder `vmhaptics hw "
                         "record --out DIR` wrote");
  }
  std::error_code ec;
  rec->folder = fs::absolute(folder, ec).lexically_normal().string();
  if (ec) rec->folder = folder;
  rec->trace_file = (fs::path(rec->folder) / "trace.csv").string();

  // the trace must be there: a replay needs its rows (meta.json may not)
  {
    struct stat tst {};
    if (::stat(rec->trace_file.c_str(), &tst) != 0 && errno == ENOENT) {
      throw RecordingError("replay: no trace.csv in '" + rec->folder +
                           "' (a recording is the folder `vmhaptics hw record "
                           "--out DIR` wrote)");
    }
  }
}

// The header's columns the reader takes: t_s and q1_rad..q6_rad, which
// must be there, and the optional ones, each group all there or not at
// all; rec's present bits say which groups are.
Layout read_layout(const runtime::TraceReader& p, Recording* rec) {
  Layout L;
  L.t = p.require("t_s");
  for (int i = 0; i < 6; ++i) {
    L.q[static_cast<std::size_t>(i)] = p.require("q" + std::to_string(i + 1) + "_rad");
  }
  L.read_error = p.find("read_error");
  L.buttons = p.find("buttons");
  L.docked = p.find("docked");
  if (L.buttons != SIZE_MAX) rec->present |= kStateButtons;
  if (L.docked != SIZE_MAX) rec->present |= kStateInkwell;
  {
    std::vector<std::string> n = names("dev_p_", kXyz, 3, "_mm");
    for (int r = 1; r <= 3; ++r) {
      for (int c = 1; c <= 3; ++c) {
        n.push_back("dev_R_" + std::to_string(r) + std::to_string(c));
      }
    }
    if (group(p, n, "the device's transform (dev_p_*_mm, dev_R_11..33)",
                &L.transform)) {
      rec->present |= kStateTransform;
    }
  }
  if (group(p, names("dev_v_", kXyz, 3, "_mm_s"),
              "the device's velocity (dev_v_*_mm_s)", &L.velocity)) {
    rec->present |= kStateVelocity;
  }
  {
    std::vector<std::string> n;
    for (int r = 1; r <= 6; ++r) {
      for (int c = 1; c <= 6; ++c) {
        n.push_back("dev_J_" + std::to_string(r) + std::to_string(c));
      }
    }
    if (group(p, n, "the device's Jacobian (dev_J_11..66)", &L.jacobian)) {
      rec->present |= kStateJacobian;
    }
  }
  {
    const char* const e[] = {"1", "2", "3"};
    const char* const q[] = {"4", "5", "6"};
    if (group(p, names("enc_", e, 3, ""), "the encoder counts (enc_1..3)", &L.enc)) {
      rec->present |= kStateEncoders;
    }
    if (group(p, names("pot_", q, 3, ""), "the gimbal pots (pot_4..6)", &L.pot)) {
      rec->present |= kStatePots;
    }
  }
  return L;
}

// The current row's read error: ok without a read_error column, else the
// error the cell names (a RecordingError if it names none).
DeviceError row_error(const runtime::TraceReader& p, const Layout& L) {
  const std::vector<std::string_view>& cells = p.cells();
  DeviceError err = DeviceError::kOk;
  if (L.read_error != SIZE_MAX &&
      !parse_device_error(std::string(cells[L.read_error]), &err)) {
    throw RecordingError(p.where(L.read_error) + ": '" +
                         std::string(cells[L.read_error]).substr(0, 40) + "' is not a read error's name "
                         "(ok, not_connected, io, timeout, sensor_fault, "
                         "invalid_command)");
  }
  return err;
}

// The current row appended to rec: its time, read error and joints (the
// trace's DH angles in the device's convention), then every group of
// columns the trace has.
void read_row(const runtime::TraceReader& p, const Layout& L, Recording* rec) {
  const double t = p.t_s();
  const DeviceError err = row_error(p, L);
  const bool good = err == DeviceError::kOk;
  // a good row's values must be finite numbers; a failed read's may be nan
  const auto value = [&](std::size_t col) {
    return good ? p.finite(col) : p.number(col);
  };
  Joints q_dh;
  for (int i = 0; i < 6; ++i) q_dh[i] = value(L.q[static_cast<std::size_t>(i)]);
  rec->time_s.push_back(t);
  rec->read_error.push_back(err);
  rec->q_device_rad.push_back(good ? dh_to_device_joints(q_dh)
                                   : Joints::Constant(std::nan("")));
  // the switches are written on every row, good or not
  if (rec->present & kStateButtons) {
    rec->buttons.push_back(
        static_cast<std::uint32_t>(p.integer(L.buttons, 0, 4294967295.0)));
  }
  if (rec->present & kStateInkwell) {
    rec->docked.push_back(static_cast<std::uint8_t>(p.integer(L.docked, 0, 1)));
  }
  if (rec->present & kStateTransform) {
    std::array<double, 12> m{};
    for (std::size_t k = 0; k < 12; ++k) m[k] = value(L.transform[k]);
    rec->transform.push_back(m);
  }
  if (rec->present & kStateVelocity) {
    std::array<double, 3> v{};
    for (std::size_t k = 0; k < 3; ++k) v[k] = value(L.velocity[k]);
    rec->velocity_mm_s.push_back(v);
  }
  if (rec->present & kStateJacobian) {
    std::array<double, 36> j{};
    for (std::size_t k = 0; k < 36; ++k) j[k] = value(L.jacobian[k]);
    rec->jacobian.push_back(j);
  }
  if (rec->present & kStateEncoders) {
    rec->encoders.push_back(int32_cells(p, L.enc));
  }
  if (rec->present & kStatePots) rec->pots.push_back(int32_cells(p, L.pot));
}

}  // namespace

Recording read_recording(const std::string& folder, const RecordingLimits& limits) {
  Recording rec;
  check_folder(folder, &rec);
  // regular file, bounds, header, cells per row, t_s: the shared reader
  runtime::TraceReader p(rec.trace_file, limits);
  const Layout L = read_layout(p, &rec);
  while (p.next()) read_row(p, L, &rec);
  if (rec.rows() == 0) {
    throw RecordingError(rec.trace_file +
                         ": no rows after the header: the recording is empty");
  }
  read_meta((fs::path(rec.folder) / "meta.json").string(), limits, &rec);
  return rec;
}

}  // namespace vmh::hw::replay
