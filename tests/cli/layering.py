"""The library's layers: prints every include of a header from an area that
the including area does not link (set(_deps_AREA ...) in CMakeLists.txt,
followed transitively), and every model-file key in the linear-model layer
`lti` (the files `pneumid identify` writes are read in `models`, the layer
above it). Exits 1 when it prints any, 2 when CMakeLists.txt names no areas.

Usage: /usr/bin/python3 tests/cli/layering.py REPOSITORY_ROOT
"""
import pathlib
import re
import sys

root = pathlib.Path(sys.argv[1])
cmake = (root / "CMakeLists.txt").read_text()
m = re.search(r"set\(PNEUMID_AREAS ([^)]*)\)", cmake)
if not m:
    sys.exit("layering: no set(PNEUMID_AREAS ...) in CMakeLists.txt")
areas = m.group(1).split()
deps = {}
for a in areas:
    d = re.search(r"set\(_deps_%s ([^)]*)\)" % a, cmake)
    deps[a] = set(re.findall(r"pneumid_(\w+)", d.group(1))) if d else set()


def below(area, seen):
    for d in deps[area] - seen:
        seen.add(d)
        below(d, seen)
    return seen


def sources(area):
    return sorted((root / "src" / area).rglob("*.[ch]pp")) + sorted(
        (root / "include/pneumid" / area).rglob("*.hpp"))


problems = []
for a in areas:
    allowed = below(a, set()) | {a}
    for f in sources(a):
        for n, line in enumerate(f.read_text().splitlines(), 1):
            inc = re.match(r'\s*#\s*include\s+"pneumid/(\w+)/', line)
            if inc and inc.group(1) in areas and inc.group(1) not in allowed:
                problems.append(f"{f.relative_to(root)}:{n}: area {a} includes {inc.group(1)}, "
                                f"which it does not link: {line.strip()}")
for f in sources("lti"):
    for n, line in enumerate(f.read_text().splitlines(), 1):
        for key in ("models", "continuous_form", "input_map", "output_map", "narx"):
            if f'"{key}"' in line:
                problems.append(f"{f.relative_to(root)}:{n}: lti reads the model-file key \"{key}\"")
print(f"{len(areas)} areas: {' '.join(areas)}")
for p in problems:
    print(p)
sys.exit(1 if problems else 0)
