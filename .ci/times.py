#!/usr/bin/env python3
"""CI's time table: where a run of .ci/run spends its time.

Reads what .ci/run leaves in its times directory (default build-times/):
  phases.tsv          one line per phase: name, wall seconds
  compile-BUILD.tsv   one line per compile or link (.ci/timed): start, end, directory, output
  ctest-BUILD.log     ctest's output, whose lines "N/M Test #K: NAME ... Passed X sec" give each
                      test's wall time
and prints Markdown tables: the phases; each target's compile and link time in each build
(seconds of one core: with -j2 the build's wall time is about half their sum); each test's time.

  .ci/times.py [DIR]
"""
import collections
import pathlib
import re
import sys

BUILDS = ("release", "sanitizer")


def target_of(directory, output):
    """The CMake target a compile or link belongs to: compiles write into CMakeFiles/T.dir/, links
    write the executable or library itself. Cross builds (firmware, web) are external projects with
    their own build directories, named as a prefix."""
    prefix = ""
    for external in ("firmware", "web"):
        if re.search(r"/%s(/|$)" % external, directory):
            prefix = external + ":"
    m = re.search(r"CMakeFiles/([^/]+)\.dir/", output)
    if m:
        return prefix + m.group(1), "compile"
    name = pathlib.PurePosixPath(output).name
    name = re.sub(r"^lib(.*)\.a$", r"\1", name)
    name = re.sub(r"\.(elf|js|wasm|html)$", "", name)
    return prefix + name, "link"


def read_compiles(path):
    seconds = collections.defaultdict(float)
    units = collections.Counter()
    if not path.exists():
        return seconds, units
    for line in path.read_text().splitlines():
        parts = line.split("\t")
        if len(parts) != 4:
            continue
        start, end, directory, output = parts
        target, kind = target_of(directory, output)
        seconds[(target, kind)] += float(end) - float(start)
        if kind == "compile":
            units[target] += 1
    return seconds, units


def read_tests(path):
    tests = {}
    if not path.exists():
        return tests
    pattern = re.compile(r"Test\s+#\d+:\s+(\S+)\s+\.*\s*(\S.*?)\s+([0-9.]+)\s+sec")
    for line in path.read_text().splitlines():
        m = pattern.search(line)
        if m:
            tests[m.group(1)] = (float(m.group(3)), m.group(2).strip())
    return tests


def fmt(x):
    return "" if x is None else "%.1f" % x


def main():
    root = pathlib.Path(sys.argv[1] if len(sys.argv) > 1 else "build-times")
    phases = root / "phases.tsv"
    if phases.exists():
        print("| phase | wall time |")
        print("|---|---|")
        total = 0.0
        for line in phases.read_text().splitlines():
            name, seconds = line.split("\t")
            total += float(seconds)
            print("| %s | %d min %02d s |" % (name, float(seconds) // 60, float(seconds) % 60))
        print("| **all** | **%d min %02d s** |" % (total // 60, total % 60))
        print()

    compiles = {b: read_compiles(root / ("compile-%s.tsv" % b)) for b in BUILDS}
    targets = sorted({t for b in BUILDS for (t, _) in compiles[b][0]},
                     key=lambda t: -sum(compiles[b][0].get((t, k), 0) for b in BUILDS for k in ("compile", "link")))
    print("| target | Release: compile (files) | link | sanitizer: compile (files) | link |")
    print("|---|---|---|---|---|")
    sums = {b: [0.0, 0.0] for b in BUILDS}
    for t in targets:
        row = [t]
        for b in BUILDS:
            seconds, units = compiles[b]
            c = seconds.get((t, "compile"))
            l = seconds.get((t, "link"))
            sums[b][0] += c or 0
            sums[b][1] += l or 0
            row += ["%s (%d)" % (fmt(c), units[t]) if c is not None else "", fmt(l)]
        print("| " + " | ".join(row) + " |")
    print("| **sum (core seconds)** | **%.0f** | **%.0f** | **%.0f** | **%.0f** |" %
          (sums["release"][0], sums["release"][1], sums["sanitizer"][0], sums["sanitizer"][1]))
    print()

    tests = {b: read_tests(root / ("ctest-%s.log" % b)) for b in BUILDS}
    names = sorted({n for b in BUILDS for n in tests[b]},
                   key=lambda n: -sum(tests[b].get(n, (0, ""))[0] for b in BUILDS))
    print("| test | Release (s) | sanitizer (s) |")
    print("|---|---|---|")
    for n in names:
        cells = []
        for b in BUILDS:
            if n in tests[b]:
                seconds, result = tests[b][n]
                cells.append("%.1f" % seconds + ("" if result == "Passed" else " " + result))
            else:
                cells.append("not run")
        print("| %s | %s |" % (n, " | ".join(cells)))
    print("| **sum (test seconds; ctest -j2 runs two at a time)** | **%.0f** | **%.0f** |" %
          tuple(sum(v[0] for v in tests[b].values()) for b in BUILDS))


if __name__ == "__main__":
    main()
