#!/usr/bin/env python3
"""Builds the API reference (`make docs`) and measures how much of it is documented.

C++: Doxygen over include/pneumid (docs/api/Doxyfile) into OUT/cpp/html, with
search. Doxygen's own warnings (broken commands, bad markup) fail the build.
Coverage counts the public names of namespace pneumid (classes, structs,
enums, functions, type aliases, variables and the public members of classes)
from Doxygen's XML; a name is documented when it has a brief or detailed
description. The build fails when the coverage falls below the floor in
docs/api/coverage_floor.txt, so that new public names come documented.

Python: pydoc's HTML page of the compiled module (its docstrings), written to
OUT/cpp/html/python.html, when the module can be imported (--python-path, e.g.
build/python). Every public function and class of the module, and every public
method and property of its classes, must then have a docstring of its own (more
than pybind11's signature line); the names without one are listed in
OUT/undocumented_python.txt and fail the build. A module that cannot be imported
(not built) is reported and skipped.

Usage: api_docs.py OUT [--python-path DIR]
"""
import argparse
import os
import pathlib
import shutil
import subprocess
import sys
import xml.etree.ElementTree as ET

ROOT = pathlib.Path(__file__).resolve().parent.parent


def text_of(node):
    return "".join(node.itertext()).strip() if node is not None else ""


def documented(node):
    return bool(text_of(node.find("briefdescription")) or text_of(node.find("detaileddescription")))


def coverage(xml_dir):
    """(documented, total, list of undocumented names) over the public API."""
    index = ET.parse(xml_dir / "index.xml").getroot()
    done, total, missing = 0, 0, []

    def count(name, node):
        nonlocal done, total
        total += 1
        if documented(node):
            done += 1
        else:
            missing.append(name)

    for comp in index.findall("compound"):
        kind = comp.get("kind")
        if kind not in ("class", "struct", "namespace"):
            continue
        name = comp.findtext("name")
        if not name.startswith("pneumid") or "internal" in name.split("::"):
            continue
        tree = ET.parse(xml_dir / (comp.get("refid") + ".xml")).getroot()
        cdef = tree.find("compounddef")
        if kind in ("class", "struct"):
            if cdef.get("prot", "public") != "public":
                continue
            count(name, cdef)
        for section in cdef.findall("sectiondef"):
            skind = section.get("kind")
            if kind == "namespace":
                wanted = skind in ("func", "enum", "typedef", "var")
            else:
                wanted = skind.startswith("public") and "slot" not in skind
            if not wanted:
                continue
            for member in section.findall("memberdef"):
                if member.get("kind") == "friend":
                    continue
                mname = member.findtext("name")
                # Defaulted/deleted special members and operators carry no text of their own.
                if mname.startswith("operator") or mname.startswith("~"):
                    continue
                count(f"{name}::{mname}", member)
    return done, total, missing


# Public functions and classes of the module, and the public methods and
# properties of its classes, with and without a docstring of their own. Prints
# "documented total" on the first line, then the names without one.
PYTHON_COVERAGE = r"""
import inspect, re, pneumid
def doc_of(name, obj):
    d = (getattr(obj, "__doc__", None) or "").strip()
    lines = d.splitlines()
    # pybind11 writes the signature first (or "Overloaded function." and one
    # signature per overload); a name documented only by it has no text.
    if not lines or not lines[0].startswith(name + "("):
        return bool(lines)
    if len(lines) > 1 and lines[1].strip() == "Overloaded function.":
        parts = re.split(r"^\d+\. " + re.escape(name) + r"\(", d, flags=re.M)[1:]
        return bool(parts) and all(any(l.strip() for l in p.splitlines()[1:]) for p in parts)
    return any(l.strip() for l in lines[1:])
done, missing = 0, []
def count(name, obj, label):
    global done
    if doc_of(name, obj):
        done += 1
    else:
        missing.append(label)
for name, obj in vars(pneumid).items():
    if name.startswith("_") or inspect.ismodule(obj):
        continue
    count(name, obj, name)
    if inspect.isclass(obj):
        for m, v in vars(obj).items():
            if m.startswith("_"):
                continue
            # A static method's own docstring is that of its function.
            if isinstance(v, staticmethod):
                v = v.__func__
            count(m, v, name + "." + m)
print(done, done + len(missing))
print("\n".join(missing))
"""


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("out", type=pathlib.Path)
    ap.add_argument("--python-path", default="")
    args = ap.parse_args()
    if shutil.which("doxygen") is None:
        sys.exit("api_docs: doxygen is not installed (scripts/setup installs it)")
    out = args.out.resolve()
    cpp = out / "cpp"
    shutil.rmtree(cpp, ignore_errors=True)
    cpp.mkdir(parents=True)
    env = dict(os.environ, PNEUMID_API_OUT=str(cpp))
    subprocess.run(["doxygen", "docs/api/Doxyfile"], cwd=ROOT, env=env, check=True)
    warnings = (cpp / "warnings.log").read_text().strip()
    if warnings:
        print(warnings, file=sys.stderr)
        sys.exit(f"api_docs: doxygen reported {len(warnings.splitlines())} warning line(s) (above)")
    done, total, missing = coverage(cpp / "xml")
    share = 100.0 * done / total
    floor = float((ROOT / "docs/api/coverage_floor.txt").read_text().split()[0])
    (out / "undocumented.txt").write_text("\n".join(sorted(missing)) + "\n")
    print(f"api_docs: C++ reference {cpp / 'html' / 'index.html'}")
    print(f"api_docs: {done} of {total} public names documented ({share:.1f} %, floor {floor} %); "
          f"the others are listed in {out / 'undocumented.txt'}")
    failures = []
    if args.python_path:
        env = dict(os.environ, PYTHONPATH=str(pathlib.Path(args.python_path).resolve()))
        probe = subprocess.run([sys.executable, "-c", "import pneumid"], env=env,
                               capture_output=True, text=True)
        if probe.returncode == 0:
            subprocess.run([sys.executable, "-m", "pydoc", "-w", "pneumid"], cwd=out, env=env,
                           check=True, stdout=subprocess.DEVNULL)
            (out / "pneumid.html").replace(out / "cpp" / "html" / "python.html")
            print(f"api_docs: Python reference {cpp / 'html' / 'python.html'}")
            counted = subprocess.run([sys.executable, "-c", PYTHON_COVERAGE], env=env,
                                     capture_output=True, text=True, check=True).stdout.splitlines()
            py_done, py_total = counted[0].split()
            py_missing = [name for name in counted[1:] if name.strip()]
            (out / "undocumented_python.txt").write_text("".join(n + "\n" for n in py_missing))
            print(f"api_docs: Python: {py_done} of {py_total} public names have a docstring"
                  + (f"; the others are listed in {out / 'undocumented_python.txt'}"
                     if py_missing else ""))
            if py_missing:
                failures.append(f"{len(py_missing)} public Python name(s) have no docstring: "
                                f"{', '.join(py_missing)} (document them in python/src)")
        else:
            print(f"api_docs: Python module not importable ({probe.stderr.strip().splitlines()[-1]}); "
                  "no Python reference", file=sys.stderr)
    if share < floor:
        failures.append(f"coverage {share:.1f} % is below the floor {floor} %: document the new "
                        f"public names (listed in {out / 'undocumented.txt'})")
    if failures:
        sys.exit("\n".join("api_docs: " + f for f in failures))


if __name__ == "__main__":
    main()
