#!/usr/bin/python3
"""The engine's house from its includes: each folder of engine/ is a room, each file pair
(NAME.hpp, NAME.cpp, with NAME_impl.hpp) a module; `#include "room/name.hpp"` an arrow. Checks that
the rooms form no circle (an arrow path from a room back to itself); prints the rooms by floor
(floor 0 includes no other room; a room's floor is one above the highest floor it includes) with
their arrows, the drawing README shows. A room with sub-folders (methods/, store/) is a house of its
own: each sub-folder a room inside it, the files directly in the room its top floor's room; the same
check (no circle, so every include goes from a higher floor to a lower one) holds inside it, and
--draw prints its floors too. --modules also lists the circles of modules (a.cpp includes b.hpp while
b.cpp includes a.hpp, or longer) and counts them as failures.

usage: /usr/bin/python3 check_rooms.py ENGINE_DIR [--draw] [--modules]
exit status 0 when there is no circle, 1 otherwise (each circle named).
"""
import os
import re
import sys
from collections import defaultdict

INCLUDE = re.compile(r'^\s*#\s*include\s+"([^"]+)"', re.M)


def graph(engine):
    """(room arrows, module arrows): room -> rooms it includes; module -> modules it includes."""
    rooms, modules, inner = defaultdict(set), defaultdict(set), defaultdict(lambda: defaultdict(set))
    for d, _, files in os.walk(engine):
        for f in files:
            if not f.endswith((".hpp", ".cpp", ".h")):
                continue
            rel = os.path.relpath(os.path.join(d, f), engine)
            if "/" not in rel:
                continue
            room, module = rel.split("/")[0], re.sub(r"_impl$", "", os.path.splitext(rel)[0])
            sub = os.path.dirname(rel)
            rooms[room]
            modules[module]
            inner[room][sub]
            with open(os.path.join(d, f), encoding="utf-8", errors="replace") as fh:
                for inc in INCLUDE.findall(fh.read()):
                    target = re.sub(r"_impl$", "", os.path.splitext(inc)[0])
                    if "/" not in inc or not os.path.exists(os.path.join(engine, inc)):
                        continue
                    if inc.split("/")[0] != room:
                        rooms[room].add(inc.split("/")[0])
                    elif os.path.dirname(inc) != sub:
                        inner[room][sub].add(os.path.dirname(inc))
                    if target != module:
                        modules[module].add(target)
    return rooms, modules, {r: dict(g) for r, g in inner.items() if len(g) > 1}


def circles(arrows):
    """The strongly connected components of more than one node (Tarjan), each sorted."""
    index, low, on, stack, out, counter = {}, {}, set(), [], [], [0]

    def visit(v):
        index[v] = low[v] = counter[0]
        counter[0] += 1
        stack.append(v)
        on.add(v)
        for w in sorted(arrows.get(v, ())):
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = []
            while True:
                w = stack.pop()
                on.discard(w)
                comp.append(w)
                if w == v:
                    break
            if len(comp) > 1:
                out.append(sorted(comp))

    sys.setrecursionlimit(10000)
    for v in sorted(arrows):
        if v not in index:
            visit(v)
    return out


def floors(arrows):
    level = {}

    def floor(r, seen=()):
        if r not in level:
            level[r] = 0 if r in seen else 1 + max((floor(t, seen + (r,)) for t in arrows[r] if t not in seen),
                                                   default=-1)
        return level[r]

    for r in arrows:
        floor(r)
    return level


def main():
    engine = sys.argv[1]
    rooms, modules, inner = graph(engine)
    bad = circles(rooms) + [c for g in inner.values() for c in circles(g)]
    bad += circles(modules) if "--modules" in sys.argv else []
    if "--draw" in sys.argv:
        for title, g in [("engine", rooms)] + [(r + "/", inner[r]) for r in sorted(inner)]:
            print(f"{title}:")
            level = floors(g)
            for f in sorted(set(level.values()), reverse=True):
                names = sorted(r for r in g if level[r] == f)
                print(f"  floor {f}: " + "   ".join(f"{r} -> {', '.join(sorted(g[r])) or '(nothing)'}" for r in names))
    for c in bad:
        print("circle: " + " -> ".join(c + [c[0]]), file=sys.stderr)
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
