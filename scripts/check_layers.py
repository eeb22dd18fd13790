#!/usr/bin/env python3
"""Checks that no include in lib/ climbs a layer (docs/architecture.md, "Layers").

lib/src/ is grouped by layer, one folder each, lowest first (FLOORS below). A file
includes only its own layer and those below; rooms on one floor do not include each
other. A file's layer:
  - lib/src/<room>/*: <room>;
  - a public header lib/include/fastcal/[internal/]<name>.h: the room of lib/src/*/<name>.cc,
    or, for a header with no .cc of its name (header-only), HEADER_ONLY below.

Every `#include "..."` of every file under lib/src/ and lib/include/fastcal/ is checked.
A folder of lib/src/ missing from FLOORS, a header whose layer is unknown, an unknown
quoted include, or a source of lib/CMakeLists.txt listed out of layer order is an error
too: a new room or header-only header is placed here, on purpose, once.

Usage: check_layers.py [repository root]. Prints every violation; exit status 1 if any.
"""

import os
import re
import sys

# Lowest first; rooms on one floor are peers (neither includes the other).
FLOORS = [
    ["util"],  # files, numbers and times as text, quoting, YAML, digests
    ["plot"],  # the SVG chart kit
    ["model"],  # the robot, its YAML, plausibility, poses, moving parts
    ["statics"],  # catenary, inverse and forward statics
    ["data"],  # datasets, column maps, trajectories, simulation
    ["calibration", "dynamics", "workspace"],
    ["report"],  # the calibration and evaluation report
    ["design"],  # survey design
    ["track"],  # a season of windows
]

# Headers with no .cc of their name, and their layer.
HEADER_ONLY = {
    "scalar.h": "statics",
    "cable_attachment.h": "model",
    "catenary_chain.h": "statics",
    "internal/csv.h": "util",
    "internal/fail.h": "util",
    "internal/json.h": "util",
    "internal/units.h": "util",
    "internal/sample_chunks.h": "util",
    "internal/dataset_column_names.h": "model",
    "internal/statics_core.h": "statics",
    "internal/statics_jet.h": "statics",
    "internal/compact_start.h": "statics",
    "internal/column_reading.h": "data",
    "internal/paper_reference.h": "report",
    "internal/report_document.h": "report",
    "internal/report_sections.h": "report",
    "internal/track_state.h": "track",
}

INCLUDE = re.compile(r'^\s*#\s*include\s+"([^"]+)"', re.MULTILINE)


def main(root):
    lib = os.path.join(root, "lib")
    src = os.path.join(lib, "src")
    public = os.path.join(lib, "include", "fastcal")
    floor_of = {room: f for f, rooms in enumerate(FLOORS) for room in rooms}
    errors = []

    rooms = sorted(d for d in os.listdir(src) if os.path.isdir(os.path.join(src, d)))
    for room in rooms:
        if room not in floor_of:
            errors.append(f"lib/src/{room}/: a room not in check_layers.py's FLOORS")

    # Layer of each header, by its name as included.
    layer = {}
    cc_room = {}
    for room in rooms:
        for name in sorted(os.listdir(os.path.join(src, room))):
            stem, ext = os.path.splitext(name)
            if ext == ".cc":
                if stem in cc_room:
                    errors.append(f"{stem}.cc in both {cc_room[stem]}/ and {room}/")
                cc_room[stem] = room
            elif ext == ".h":
                layer[f"{room}/{name}"] = room  # a room's private header
    for dirpath, _, names in os.walk(public):
        for name in names:
            if not name.endswith(".h"):
                continue
            rel = os.path.relpath(os.path.join(dirpath, name), public).replace(os.sep, "/")
            stem = name[:-2]
            if rel in HEADER_ONLY:
                layer["fastcal/" + rel] = HEADER_ONLY[rel]
                if stem in cc_room:
                    errors.append(f"fastcal/{rel}: in HEADER_ONLY but has {cc_room[stem]}/{stem}.cc")
            elif stem in cc_room:
                layer["fastcal/" + rel] = cc_room[stem]
            else:
                errors.append(f"fastcal/{rel}: no .cc of its name and not in HEADER_ONLY")
    generated = {"fastcal/version.h": "util"}  # from version.h.in
    layer.update(generated)

    # Every file and its includes.
    files = []
    for room in rooms:
        for name in sorted(os.listdir(os.path.join(src, room))):
            if name.endswith((".cc", ".h")):
                files.append((f"lib/src/{room}/{name}", room))
    for header in sorted(h for h in layer if h.startswith("fastcal/") and h not in generated):
        if layer[header] in floor_of:
            files.append(("lib/include/" + header, layer[header]))
    for path, room in files:
        if room not in floor_of:
            continue
        with open(os.path.join(root, path), encoding="utf-8") as f:
            text = f.read()
        for match in INCLUDE.finditer(text):
            included = match.group(1)
            line = text.count("\n", 0, match.start()) + 1
            target = layer.get(included)
            if target is None:
                errors.append(f"{path}:{line}: \"{included}\": a header of no known layer")
            elif target not in floor_of:
                continue
            elif floor_of[target] > floor_of[room]:
                errors.append(f"{path}:{line}: {room} includes \"{included}\" of the higher "
                              f"layer {target}")
            elif floor_of[target] == floor_of[room] and target != room:
                errors.append(f"{path}:{line}: {room} includes \"{included}\" of {target}, "
                              f"a room on the same floor")

    # lib/CMakeLists.txt lists the sources by layer, lowest first.
    with open(os.path.join(lib, "CMakeLists.txt"), encoding="utf-8") as f:
        listed = re.findall(r"^\s*src/([a-z_]+)/[^\s]+\.cc\s*$", f.read(), re.MULTILINE)
    highest = -1
    for room in listed:
        floor = floor_of.get(room, -1)
        if floor < highest:
            errors.append(f"lib/CMakeLists.txt: a source of {room}/ listed after a higher layer's")
            break
        highest = max(highest, floor)

    for e in errors:
        print(e)
    if errors:
        print(f"check_layers: {len(errors)} error(s); the layers are in scripts/check_layers.py "
              "and docs/architecture.md")
        return 1
    print(f"check_layers: {len(files)} files, no include climbs a layer")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1] if len(sys.argv) > 1 else
                  os.path.join(os.path.dirname(os.path.abspath(__file__)), "..")))
