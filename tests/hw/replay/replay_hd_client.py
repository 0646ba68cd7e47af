#!/usr/bin/env python3
"""A ctypes client of libHD.so on a recording: `vmhaptics hw record
--device emulator` makes one, VMH_HD_DEVICE=replay:DIR serves it, and a
scheduler callback reads HD_CURRENT_JOINT_ANGLES, HD_CURRENT_GIMBAL_ANGLES
and HD_CURRENT_POSITION with the tick's time (vmhdGetSchedulerTime). Each
sample is compared with the trace.csv row of that time, read here with the
csv module: the angles from the DH columns by hand (t1 = -q1, t2 = q2,
t3 = q2 + q3, t4 = -q4, t5 = q5, t6 = -q6, rad), the position from
dev_p_*_mm (mm, device frame).

Run with VMH_HD_CLOCK=lockstep (tests/hw/replay/CMakeLists.txt), so that
tick k reads row k however busy the host. Prints one JSON line; exit 0
when every sample matches, 1 when one does not, 2 when something failed.
"""
import argparse
import csv
import ctypes
import json
import os
import subprocess
import sys
import time

HD_SUCCESS = 0
HD_CURRENT_POSITION = 0x2050
HD_CURRENT_JOINT_ANGLES = 0x2100
HD_CURRENT_GIMBAL_ANGLES = 0x2150
HD_INVALID_HANDLE = 0xFFFFFFFF
HD_CALLBACK_DONE = 0
HD_CALLBACK_CONTINUE = 1
HD_DEFAULT_SCHEDULER_PRIORITY = 32767


class HDErrorInfo(ctypes.Structure):
    _fields_ = [("errorCode", ctypes.c_uint),
                ("internalErrorCode", ctypes.c_int),
                ("hHD", ctypes.c_uint)]


CALLBACK = ctypes.CFUNCTYPE(ctypes.c_uint, ctypes.c_void_p)


def recorded_rows(trace):
    """{round(t_s * 1e6): (t1..t6, (x, y, z))} from trace.csv"""
    rows = {}
    with open(trace, newline="") as f:
        for r in csv.DictReader(f):
            if r["read_error"] != "ok":
                continue
            q = [float(r["q%d_rad" % i]) for i in range(1, 7)]
            t = [-q[0], q[1], q[1] + q[2], -q[3], q[4], -q[5]]
            p = [float(r["dev_p_%s_mm" % a]) for a in "xyz"]
            rows[round(float(r["t_s"]) * 1e6)] = (t, p)
    return rows


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--vmhaptics", required=True)
    ap.add_argument("--dir", required=True, help="where the recording goes")
    ap.add_argument("--samples", type=int, default=400)
    args = ap.parse_args()

    rec = subprocess.run([args.vmhaptics, "hw", "record", "--device", "emulator",
                          "--duration", "1", "--quiet", "--out", args.dir],
                         capture_output=True, text=True)
    if rec.returncode != 0:
        print(json.dumps({"error": "hw record failed", "stderr": rec.stderr}))
        return 2
    rows = recorded_rows(os.path.join(args.dir, "trace.csv"))
    os.environ["VMH_HD_DEVICE"] = "replay:" + args.dir

    hd = ctypes.CDLL("libHD.so")
    hd.hdGetError.restype = HDErrorInfo
    hd.hdGetErrorString.restype = ctypes.c_char_p
    hd.hdGetErrorString.argtypes = [ctypes.c_uint]
    hd.hdInitDevice.restype = ctypes.c_uint
    hd.hdInitDevice.argtypes = [ctypes.c_char_p]
    hd.hdGetCurrentDevice.restype = ctypes.c_uint
    hd.hdScheduleAsynchronous.restype = ctypes.c_ulong
    hd.hdScheduleAsynchronous.argtypes = [CALLBACK, ctypes.c_void_p, ctypes.c_ushort]
    hd.hdGetDoublev.argtypes = [ctypes.c_uint, ctypes.POINTER(ctypes.c_double)]
    hd.hdBeginFrame.argtypes = [ctypes.c_uint]
    hd.hdEndFrame.argtypes = [ctypes.c_uint]
    hd.hdUnschedule.argtypes = [ctypes.c_ulong]
    hd.hdDisableDevice.argtypes = [ctypes.c_uint]
    hd.vmhdGetSchedulerTime.restype = ctypes.c_double

    errors = []

    def check(where):
        while True:
            e = hd.hdGetError()
            if e.errorCode == HD_SUCCESS:
                return
            errors.append({"where": where, "code": e.errorCode,
                           "text": hd.hdGetErrorString(e.errorCode).decode()})

    h = hd.hdInitDevice(b"Default Device")
    check("hdInitDevice")
    if h == HD_INVALID_HANDLE:
        print(json.dumps({"error": "hdInitDevice failed", "errors": errors}))
        return 2

    samples = []

    def servo(_):
        hd.hdBeginFrame(hd.hdGetCurrentDevice())
        ja = (ctypes.c_double * 3)()
        ga = (ctypes.c_double * 3)()
        p = (ctypes.c_double * 3)()
        hd.hdGetDoublev(HD_CURRENT_JOINT_ANGLES, ja)
        hd.hdGetDoublev(HD_CURRENT_GIMBAL_ANGLES, ga)
        hd.hdGetDoublev(HD_CURRENT_POSITION, p)
        t = hd.vmhdGetSchedulerTime()
        hd.hdEndFrame(hd.hdGetCurrentDevice())
        samples.append((t, list(ja) + list(ga), list(p)))
        return HD_CALLBACK_DONE if len(samples) >= args.samples else HD_CALLBACK_CONTINUE

    cb = CALLBACK(servo)
    handle = hd.hdScheduleAsynchronous(cb, None, HD_DEFAULT_SCHEDULER_PRIORITY)
    hd.hdStartScheduler()
    check("hdStartScheduler")
    deadline = time.monotonic() + 60.0
    while len(samples) < args.samples and time.monotonic() < deadline:
        time.sleep(0.02)
    hd.hdStopScheduler()
    hd.hdUnschedule(handle)
    hd.hdDisableDevice(h)
    errors = [e for e in errors if e["where"] != "hdUnschedule"]

    matched, missing, max_dq, max_dp = 0, [], 0.0, 0.0
    for t, q, p in samples:
        row = rows.get(round(t * 1e6))
        if row is None:
            missing.append(t)
            continue
        matched += 1
        max_dq = max(max_dq, max(abs(a - b) for a, b in zip(q, row[0])))
        max_dp = max(max_dp, max(abs(a - b) for a, b in zip(p, row[1])))
    ok = (len(samples) >= args.samples and not missing and max_dq < 1e-8
          and max_dp < 1e-6 and not errors)
    print(json.dumps({"samples": len(samples), "matched": matched,
                      "first_t_s": samples[0][0] if samples else None,
                      "max_abs_dq_rad": max_dq, "max_abs_dp_mm": max_dp,
                      "times_not_recorded": missing[:5], "errors": errors}))
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
