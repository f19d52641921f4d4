#!/usr/bin/env python3
"""The objects of the lane kernels (engine/methods/closed_form/lanes_x4.cpp, _x8.cpp and
engine/methods/path_global/terms_x4.cpp, _x8.cpp: built with -mavx2, or -mavx512f -mavx512dq) must
define no inline function or template instance that another object may define too: the linker keeps
one copy of such (weak) symbols, and if it kept this object's copy, code built for older processors would
run instructions they lack. Every weak function defined here must be specific to the object's lane type (F64x4 / M64x4, or F64x8 / M64x8), and each kernel's entry must be
there once. Usage: check_lane_objects.py x4|x8 OBJECT..."""
import subprocess
import sys


def main():
    width, objects = sys.argv[1], sys.argv[2:]
    tags = {"x4": ("F64x4", "M64x4"), "x8": ("F64x8", "M64x8")}[width]
    entry_names = (f"ks::kernel::run_{width}(", f"ks::terms_3r_{width}(", f"ks::samples_3r_{width}(")
    bad, entries = [], {e: 0 for e in entry_names}
    for obj in objects:
        out = subprocess.run(["nm", "-C", "--defined-only", obj], check=True, capture_output=True, text=True).stdout
        for line in out.splitlines():
            parts = line.split(None, 2)
            if len(parts) < 3:
                continue
            kind, name = parts[1], parts[2]
            for entry in entry_names:
                if kind == "T" and name.startswith(entry):
                    entries[entry] += 1
            if name == "DW.ref.__gxx_personality_v0":  # the C++ runtime's, the same in every object
                continue
            # weak code only: weak objects (V, u: typeinfo that UBSan's function checks emit, guard
            # variables) hold data, no instructions, so whichever copy the linker keeps is the same
            if kind in ("W", "i") and not any(t in name for t in tags):
                bad.append(f"{obj}: {kind} {name}")
    for b in bad:
        print("shared symbol:", b)
    for entry, count in entries.items():
        if count != 1:
            print(f"expected the entry {entry}...) once, found it {count} times")
    return 1 if bad or any(count != 1 for count in entries.values()) else 0


if __name__ == "__main__":
    sys.exit(main())
