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
OUT/python.html, when the module can be imported (PYTHONPATH=build/python).

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
# properties of its classes, with and without a docstring of their own.
PYTHON_COVERAGE = """
import inspect, pneumid
done = total = 0
def doc_of(obj):
    d = getattr(obj, "__doc__", None) or ""
    # pybind11 writes the signature first; a name documented only by it has no text.
    lines = [l for l in d.strip().splitlines()[1:] if l.strip()] if "(" in d.split("\\n")[0] else d.strip().splitlines()
    return bool(lines)
for name, obj in vars(pneumid).items():
    if name.startswith("_") or inspect.ismodule(obj):
        continue
    total += 1; done += doc_of(obj)
    if inspect.isclass(obj):
        for m, v in vars(obj).items():
            if m.startswith("_"):
                continue
            total += 1; done += doc_of(v)
print(done, total)
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
                                     capture_output=True, text=True, check=True).stdout.split()
            print(f"api_docs: Python: {counted[0]} of {counted[1]} public names have a docstring")
        else:
            print(f"api_docs: Python module not importable ({probe.stderr.strip().splitlines()[-1]}); "
                  "no Python reference", file=sys.stderr)
    if share < floor:
        sys.exit(f"api_docs: coverage {share:.1f} % is below the floor {floor} %: document the new "
                 f"public names (listed in {out / 'undocumented.txt'})")


if __name__ == "__main__":
    main()
