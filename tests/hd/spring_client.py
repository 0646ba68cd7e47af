#!/usr/bin/env python3
"""A ctypes client of libHD.so, written the way the public Python clients
are (load the library by name, ask for the current device before init,
open "Default Device", read the transform as a 4x4 array whose last column
holds the position, check hdGetError after every call, send
HD_CURRENT_FORCE from an asynchronous scheduler callback).

It closes a spring (K_N_per_mm) toward a point TARGET_OFFSET_mm from where
the stylus starts, for --seconds, and prints one JSON line: the distance
to the point at the start and at the end (mm), the frames the callback ran,
and the errors seen. Exit status 0 when the stylus ended nearer the point
than it started, 1 otherwise, 2 when the library failed.

Run on the project's library:  LD_LIBRARY_PATH=build/lib python3 spring_client.py
"""
import argparse
import ctypes
import json
import math
import sys
import time

HD_SUCCESS = 0
HD_CURRENT_TRANSFORM = 0x2052
HD_CURRENT_POSITION = 0x2050
HD_CURRENT_BUTTONS = 0x2000
HD_CURRENT_FORCE = 0x2700
HD_FORCE_OUTPUT = 0x4000
HD_INVALID_HANDLE = 0xFFFFFFFF
HD_CALLBACK_CONTINUE = 1
HD_DEFAULT_SCHEDULER_PRIORITY = 32767


class HDErrorInfo(ctypes.Structure):
    _fields_ = [("errorCode", ctypes.c_uint),
                ("internalErrorCode", ctypes.c_int),
                ("hHD", ctypes.c_uint)]


CALLBACK = ctypes.CFUNCTYPE(ctypes.c_uint, ctypes.c_void_p)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--seconds", type=float, default=2.0)
    ap.add_argument("--stiffness", type=float, default=0.05, help="N/mm")
    ap.add_argument("--offset", type=float, nargs=3, default=[30.0, 20.0, 0.0],
                    help="the spring's point from the start, mm (device frame)")
    ap.add_argument("--device", default="Default Device")
    args = ap.parse_args()

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
    hd.hdSetDoublev.argtypes = [ctypes.c_uint, ctypes.POINTER(ctypes.c_double)]
    hd.hdGetIntegerv.argtypes = [ctypes.c_uint, ctypes.POINTER(ctypes.c_int)]
    hd.hdBeginFrame.argtypes = [ctypes.c_uint]
    hd.hdEndFrame.argtypes = [ctypes.c_uint]
    hd.hdUnschedule.argtypes = [ctypes.c_ulong]
    hd.hdDisableDevice.argtypes = [ctypes.c_uint]

    errors = []

    def check(where):
        while True:
            e = hd.hdGetError()
            if e.errorCode == HD_SUCCESS:
                return
            errors.append({"where": where, "code": e.errorCode,
                           "text": hd.hdGetErrorString(e.errorCode).decode()})

    # as pyOpenHaptics does: the current device asked for before any init
    hd.hdGetCurrentDevice()
    check("hdGetCurrentDevice before init")
    errors.clear()  # no device yet: a BAD_HANDLE there is expected

    h = hd.hdInitDevice(args.device.encode())
    check("hdInitDevice")
    if h == HD_INVALID_HANDLE:
        print(json.dumps({"error": "hdInitDevice failed", "errors": errors}))
        return 2
    hd.hdEnable(HD_FORCE_OUTPUT)
    check("hdEnable")

    state = {"frames": 0, "start": None, "pos": None}

    def transform_position():
        t = (ctypes.c_double * 16)()
        hd.hdGetDoublev(HD_CURRENT_TRANSFORM, t)
        # column-major: as a 4x4 row-by-row array M[r][c] = t[c * 4 + r],
        # the position is the last column
        m = [[t[c * 4 + r] for c in range(4)] for r in range(4)]
        return [m[0][3], m[1][3], m[2][3]]

    def servo(_):
        hd.hdBeginFrame(hd.hdGetCurrentDevice())
        p = transform_position()
        if state["start"] is None:
            state["start"] = p
        target = [state["start"][i] + args.offset[i] for i in range(3)]
        f = (ctypes.c_double * 3)(*[args.stiffness * (target[i] - p[i])
                                    for i in range(3)])
        hd.hdSetDoublev(HD_CURRENT_FORCE, f)
        hd.hdEndFrame(hd.hdGetCurrentDevice())
        check("servo callback")
        state["pos"] = p
        state["frames"] += 1
        return HD_CALLBACK_CONTINUE

    cb = CALLBACK(servo)
    handle = hd.hdScheduleAsynchronous(cb, None, HD_DEFAULT_SCHEDULER_PRIORITY)
    check("hdScheduleAsynchronous")
    hd.hdStartScheduler()
    check("hdStartScheduler")
    # the servo callback appends its own errors from the servo thread (the
    # impulse limit at the spring's onset): only the start's count here
    started = [e for e in errors if e["where"] == "hdStartScheduler"]
    if started:
        hd.hdStopScheduler()  # never leave the servo thread calling into
        hd.hdDisableDevice(h)  # an interpreter that is shutting down
        print(json.dumps({"error": "the scheduler did not start", "errors": started}))
        return 2
    time.sleep(args.seconds)
    hd.hdStopScheduler()
    check("hdStopScheduler")
    hd.hdUnschedule(handle)
    check("hdUnschedule")
    hd.hdDisableDevice(h)
    check("hdDisableDevice")

    if state["start"] is None:
        print(json.dumps({"error": "the callback never ran", "errors": errors}))
        return 2
    target = [state["start"][i] + args.offset[i] for i in range(3)]
    d0 = math.dist(state["start"], target)
    d1 = math.dist(state["pos"], target)
    print(json.dumps({"start_distance_mm": d0, "end_distance_mm": d1,
                      "frames": state["frames"], "errors": errors}))
    return 0 if d1 < d0 else 1


if __name__ == "__main__":
    sys.exit(main())
