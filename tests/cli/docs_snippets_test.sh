#!/usr/bin/env bash
# The code shown in README.md and docs/*.md works, and the output shown is
# the output printed today:
#  - C++: every ```cpp / ```c++ block is compiled against the installed
#    library (`cmake --install` of the build tree into a scratch prefix, then
#    one small CMake project with find_package(pneumid), as tests/consumer/).
#    A block with `int main` is built as a program and run (in the scratch
#    directory, unless it reads argv/argc). Any other block is a fragment,
#    checked with -fsyntax-only: its #include lines first, then the block at
#    namespace scope when it defines functions, classes or namespaces, else
#    inside a function body in which t, u and y (the sample vectors the prose
#    around fragments works on) are declared as Eigen::VectorXd; a
#    declaration of the fragment shadows them. Errors point at page:line.
#  - Python: every ```python block runs with Debian's /usr/bin/python3 and the
#    built module (BUILD/python), the blocks of one page in order in one
#    interpreter (a later block uses an earlier one's names).
#  - Output: a fenced block whose first line is a concrete `pneumid ...`
#    command (or `$ pneumid ...`; later `$ ` lines start further commands),
#    followed by what it prints, and preceded by
#        <!-- output checked: rtol=1e-3 [atol=A] [skip=REGEX] -->
#    is run in the scratch directory after the page's earlier concrete
#    commands; its stdout then stderr must have the same lines (lines matching
#    skip= are left out on both sides, e.g. timings), the same text around the
#    numbers (blanks collapsed) and every number within
#    |actual - shown| <= atol + rtol * max(|actual|, |shown|).
#    Output blocks without the marker are listed as notes.
# A block opts out with an HTML comment on the line before it:
#    <!-- not compiled: REASON -->   (C++)      <!-- not run: REASON -->   (Python)
# The reason is printed. Everything runs in one scratch directory holding
# links to the repository's data/ and config/ folders.
# Usage: bash docs_snippets_test.sh /path/to/pneumid   (the build directory is
# the program's folder: its python/ module and its install rules are used)
source "$(dirname "${BASH_SOURCE[0]}")/lib.sh" "$@"

# What the docs hold (2026-11): a parser that stops matching finds fewer and
# fails here. Raise these when blocks are added.
MIN_CPP_BLOCKS=3       # C++ blocks compiled (programs and fragments)
MIN_PYTHON_BLOCKS=3    # Python blocks run
MIN_OUTPUT_BLOCKS=2    # command + output blocks checked
MIN_NUMBERS=53         # numbers compared in them

PNEUMID=$(realpath "$PNEUMID")
BUILD=$(dirname "$PNEUMID")
mkdir "$TMP/work"
ln -s "$SRC/data" "$TMP/work/data"
ln -s "$SRC/config" "$TMP/work/config"

"$PY" - "$SRC" "$PNEUMID" "$BUILD" "$TMP" \
  "$MIN_CPP_BLOCKS" "$MIN_PYTHON_BLOCKS" "$MIN_OUTPUT_BLOCKS" "$MIN_NUMBERS" <<'PYEOF' ||
import concurrent.futures, glob, json, os, re, shlex, subprocess, sys, threading, time

src, pneumid, build, tmp = sys.argv[1:5]
min_cpp, min_py, min_out, min_numbers = map(int, sys.argv[5:9])
work = os.path.join(tmp, "work")
pages = [os.path.join(src, "README.md")] + sorted(glob.glob(os.path.join(src, "docs", "*.md")))
started = time.monotonic()

failures = []
lock = threading.Lock()


def fail(where, message):
    with lock:
        failures.append(f"{where}: {message}")
        print(f"FAIL: {where}: {message}", file=sys.stderr, flush=True)


def note(message):
    with lock:
        print(message, flush=True)


def tail(text, n=3000):
    text = text.strip()
    return text if len(text) <= n else "..." + text[-n:]


# ---------------------------------------------------------------------------
# Fenced blocks of the pages
# ---------------------------------------------------------------------------
class Block:
    def __init__(self, page, rel, fence_line, lang, lines, before):
        self.page, self.rel = page, rel
        self.line = fence_line + 1      # 1-based number of the block's first line
        self.lang, self.lines, self.before = lang, lines, before

    @property
    def where(self):
        return f"{self.rel}:{self.line}"

    def comment(self, pattern):
        m = re.match(r"\s*<!--\s*" + pattern + r"\s*(.*?)\s*-->\s*$", self.before)
        return m.group(1) if m else None


def blocks_of(page):
    rel = os.path.relpath(page, src)
    lines = open(page, encoding="utf-8").read().split("\n")
    out, i = [], 0
    while i < len(lines):
        m = re.match(r"^( *)```\s*([\w+-]*)", lines[i])
        if not m:
            i += 1
            continue
        j = i + 1
        while j < len(lines) and not lines[j].lstrip().startswith("```"):
            j += 1
        k = i - 1
        while k >= 0 and not lines[k].strip():
            k -= 1
        indent = len(m.group(1))        # a fence indented in a list item
        body = [l[indent:] if l[:indent].isspace() else l for l in lines[i + 1:j]]
        out.append(Block(page, rel, i + 1, m.group(2).lower(), body,
                         lines[k] if k >= 0 else ""))
        i = j + 1
    return out


all_blocks = {page: blocks_of(page) for page in pages}


def opt_out(block, words, label):
    reason = block.comment(r"not (?:" + words + r"):")
    if reason is not None:
        note(f"{block.where}: {label} block not {words.split('|')[0]}: {reason}")
    return reason is not None


# ---------------------------------------------------------------------------
# 1. C++ blocks
# ---------------------------------------------------------------------------
cpp_counts = {"programs": 0, "fragments": 0, "run": 0}
cpp_dir = os.path.join(tmp, "cpp")
prefix = os.path.join(tmp, "prefix")
PREAMBLE_NAMES = ("t", "u", "y")
NAMESPACE_SCOPE = re.compile(
    r"^\s*(namespace|struct|class|template|enum|union)\b"
    r"|^(?!(?:else|return|if|for|while|switch|do|case)\b)"
    r"[A-Za-z_][\w:<>,*& ]*[\s*&]+~?[A-Za-z_][\w:]*\s*\([^;{}]*\)\s*"
    r"(const|noexcept|override|final|->\s*[\w:<>]+|\s)*\{", re.M)


def cache_value(name):
    try:
        for line in open(os.path.join(build, "CMakeCache.txt"), encoding="utf-8"):
            if line.startswith(name + ":"):
                return line.split("=", 1)[1].strip()
    except OSError:
        pass
    return None


def cpp_sources():
    """(block, kind, file name, text) of each C++ block to compile."""
    out = []
    for page in pages:
        for b in all_blocks[page]:
            if b.lang not in ("cpp", "c++") or opt_out(b, "compiled", "C++"):
                continue
            name = re.sub(r"\W", "_", f"{b.rel[:-3]}_{b.line}")
            code = "\n".join(b.lines)
            if re.search(r"\bint\s+main\s*\(", code):
                out.append((b, "program", f"prog_{name}.cpp",
                            f'#line {b.line} "{b.rel}"\n{code}\n'))
                continue
            includes = [l for l in b.lines if l.lstrip().startswith("#include")]
            body = "\n".join("" if l.lstrip().startswith("#include") else l for l in b.lines)
            head = "\n".join(includes) + "\n#include <Eigen/Core>\n#include <string>\n#include <vector>\n"
            if NAMESPACE_SCOPE.search(body):
                text = f'{head}#line {b.line} "{b.rel}"\n{body}\n'
            else:
                decl = ", ".join(f"{n} = Eigen::VectorXd::LinSpaced(11, 0.0, 1.0)"
                                 for n in PREAMBLE_NAMES)
                text = (f"{head}[[maybe_unused]] static void docs_snippet() {{\n"
                        f"  [[maybe_unused]] Eigen::VectorXd {decl};\n  {{\n"
                        f'#line {b.line} "{b.rel}"\n{body}\n  }}\n}}\n')
            out.append((b, "fragment", f"frag_{name}.cpp", text))
    return out


def run_logged(cmd, where, timeout=600, show_command=True, **kw):
    shown = " ".join(cmd) if show_command else os.path.basename(cmd[0])
    try:
        r = subprocess.run(cmd, capture_output=True, text=True, timeout=timeout, **kw)
    except subprocess.TimeoutExpired:
        fail(where, f"timed out after {timeout} s: {shown}")
        return None
    if r.returncode != 0:
        fail(where, f"exit {r.returncode}: {shown}\n{tail(r.stdout + r.stderr)}")
        return None
    return r


programs_built = []


def compile_cpp(sources):
    """Installs, configures once, checks the fragments, builds the programs."""
    if not sources:
        return
    for attempt in range(2):    # a build running next door may be mid-write
        r = subprocess.run(["cmake", "--install", build, "--prefix", prefix],
                           capture_output=True, text=True)
        if r.returncode == 0:
            break
        time.sleep(5)
    else:
        fail("C++", f"cmake --install {build} failed: {tail(r.stdout + r.stderr)}")
        return
    os.makedirs(cpp_dir)
    frags = [s for s in sources if s[1] == "fragment"]
    progs = [s for s in sources if s[1] == "program"]
    cm = ["cmake_minimum_required(VERSION 3.22)", "project(docs_snippets LANGUAGES CXX)",
          "set(CMAKE_CXX_STANDARD 20)", "set(CMAKE_CXX_STANDARD_REQUIRED ON)",
          "set(CMAKE_CXX_EXTENSIONS OFF)", "set(CMAKE_EXPORT_COMPILE_COMMANDS ON)",
          "find_package(pneumid REQUIRED)"]
    for _, _, name, text in sources:
        with open(os.path.join(cpp_dir, name), "w", encoding="utf-8") as f:
            f.write(text)
    if frags:
        cm.append("add_library(fragments OBJECT EXCLUDE_FROM_ALL "
                  + " ".join(s[2] for s in frags) + ")")
        cm.append("target_link_libraries(fragments PRIVATE pneumid::pneumid)")
    for _, _, name, _ in progs:
        target = name[:-4]
        cm.append(f"add_executable({target} {name})")
        cm.append(f"target_link_libraries({target} PRIVATE pneumid::pneumid)")
    with open(os.path.join(cpp_dir, "CMakeLists.txt"), "w") as f:
        f.write("\n".join(cm) + "\n")
    configure = ["cmake", "-S", cpp_dir, "-B", os.path.join(cpp_dir, "build"),
                 "-G", "Unix Makefiles", f"-DCMAKE_PREFIX_PATH={prefix}"]
    compiler = cache_value("CMAKE_CXX_COMPILER")
    if compiler and os.path.isabs(compiler):
        configure.append(f"-DCMAKE_CXX_COMPILER={compiler}")
    if cache_value("PNEUMID_SANITIZE") == "ON":   # the libraries need the runtime
        flags = "-fsanitize=address,undefined"
        configure += [f"-DCMAKE_CXX_FLAGS={flags}", f"-DCMAKE_EXE_LINKER_FLAGS={flags}"]
    if run_logged(configure, "C++: configure of the snippet project") is None:
        return
    commands = {}
    for e in json.load(open(os.path.join(cpp_dir, "build", "compile_commands.json"))):
        words = e["arguments"] if "arguments" in e else shlex.split(e["command"])
        commands[os.path.basename(e["file"])] = (e["directory"], words)

    def syntax_check(source):
        b, _, name, _ = source
        directory, words = commands[name]
        cmd = []
        skip = False
        for w in words:
            if skip:
                skip = False
            elif w == "-o":
                skip = True
            else:
                cmd.append("-fsyntax-only" if w == "-c" else w)
        if run_logged(cmd, f"{b.where}: C++ fragment does not compile", cwd=directory,
                      show_command=False):
            with lock:
                cpp_counts["fragments"] += 1

    note(f"C++: installed and configured at {time.monotonic() - started:.1f} s")
    with concurrent.futures.ThreadPoolExecutor(2) as pool:
        list(pool.map(syntax_check, frags))
    note(f"C++: {len(frags)} fragment(s) checked at {time.monotonic() - started:.1f} s")
    if progs:
        r = subprocess.run(["cmake", "--build", os.path.join(cpp_dir, "build"), "-j2",
                            "--", "-k"], capture_output=True, text=True)
        for b, _, name, _ in progs:
            exe = os.path.join(cpp_dir, "build", name[:-4])
            if os.path.exists(exe):
                cpp_counts["programs"] += 1
                programs_built.append((b, exe))
            else:
                errors = [l for l in (r.stdout + r.stderr).split("\n") if b.rel in l or name in l]
                fail(b.where, "C++ program does not build:\n" + tail("\n".join(errors)
                                                                       or r.stdout + r.stderr))


def run_programs():
    for b, exe in programs_built:
        code = "\n".join(b.lines)
        if re.search(r"\bargv\s*\[\s*[1-9]|\bargc\s*[<>=!]", code):
            note(f"{b.where}: C++ program compiled, not run (it takes arguments)")
            continue
        if run_logged([exe], f"{b.where}: C++ program", timeout=120, cwd=work):
            cpp_counts["run"] += 1


# ---------------------------------------------------------------------------
# 2. Python blocks
# ---------------------------------------------------------------------------
RUNNER = r'''
import json, sys, time, traceback
blocks, results = json.load(open(sys.argv[1])), []
scope = {"__name__": "__main__"}
for b in blocks:
    start = time.monotonic()
    try:
        code = compile("\n" * (b["line"] - 1) + b["code"], b["path"], "exec")
        exec(code, scope)
        error = None
    except (Exception, SystemExit):
        error = traceback.format_exc()
    sys.stdout.flush()
    results.append({"error": error, "seconds": time.monotonic() - start})
    json.dump(results, open(sys.argv[2], "w"))
'''
python_count = 0


def run_python():
    global python_count
    module_dir = os.path.join(build, "python")
    if not glob.glob(os.path.join(module_dir, "pneumid*.so")):
        if cache_value("PNEUMID_BUILD_PYTHON") == "OFF":
            note("python blocks: not run (PNEUMID_BUILD_PYTHON is OFF in this build)")
            return False
        fail("python", f"no module pneumid*.so in {module_dir}")
        return True
    runner = os.path.join(tmp, "run_blocks.py")
    with open(runner, "w") as f:
        f.write(RUNNER)
    env = dict(os.environ, PYTHONPATH=module_dir, MPLBACKEND="Agg")
    for page in pages:
        blocks = [b for b in all_blocks[page] if b.lang in ("python", "py", "python3")]
        blocks = [b for b in blocks if not opt_out(b, "run|compiled", "python")]
        if not blocks:
            continue
        name = re.sub(r"\W", "_", os.path.relpath(page, src))
        spec, result = os.path.join(tmp, f"{name}.blocks.json"), os.path.join(tmp, f"{name}.out.json")
        json.dump([{"path": page, "line": b.line, "code": "\n".join(b.lines)} for b in blocks],
                  open(spec, "w"))
        try:
            r = subprocess.run([sys.executable, runner, spec, result], cwd=work, env=env,
                               capture_output=True, text=True, timeout=300)
            output = r.stdout + r.stderr
        except subprocess.TimeoutExpired as e:
            partial = e.stdout or b""
            output = "timed out after 300 s\n" + (partial.decode(errors="replace")
                                                   if isinstance(partial, bytes) else partial)
        results = json.load(open(result)) if os.path.exists(result) else []
        for i, b in enumerate(blocks):
            if i < len(results) and results[i]["error"] is None:
                python_count += 1
                note(f"{b.where}: python block ran ({results[i]['seconds']:.1f} s)")
            elif i < len(results):
                fail(b.where, f"python block raised:\n{results[i]['error'].rstrip()}\n"
                              f"output of the page's blocks:\n{tail(output, 1500)}")
            else:
                fail(b.where, f"python block did not finish:\n{tail(output)}")
    return True


# ---------------------------------------------------------------------------
# 3. Printed output
# ---------------------------------------------------------------------------
PLACEHOLDER = re.compile(r"(^|[\s=,:])(DATA|MODEL|DIR|FILE|PLANT|SIGNAL|ADDR|HOST|PORT|SPEC|"
                         r"RULE|TS|N|K|X|T|C|S|Y|D|Q|M\d)(\b|$)")
NOT_RUN = re.compile(r"udp://|comedi|plant-server|pneumid app\b")
NUMBER = re.compile(r"(?<![\w.])[-+]?(?:\d+(?:\.\d*)?|\.\d+)(?:[eE][-+]?\d+)?(?![\w.]*\d)")
COMMAND = re.compile(r"^(?:\$ )?(?:pneumid|\$B) ")
output_blocks = 0
numbers_compared = 0


def concrete(text):
    """argv of a runnable documented command, or None (synopsis, network, ...)."""
    text = re.sub(r"^\$ ", "", text.strip())
    text = re.sub(r"^\$B ", "pneumid ", text)
    code = text.split("#")[0]
    if ("[" in text or "|" in code or "..." in text or PLACEHOLDER.search(code)
            or NOT_RUN.search(text)):
        return None
    try:
        words = [w for w in shlex.split(text, comments=True) if w != "&"]
    except ValueError:
        return None
    if len(words) < 2 or words[0] != "pneumid" or not re.match(r"^[a-z][a-z-]*$", words[1]):
        return None
    return words


def join_continued(lines, i):
    """(command text, index after it) of the command starting at lines[i]."""
    text = lines[i].strip()
    i += 1
    while text.endswith("\\") and i < len(lines):
        text = text[:-1] + " " + lines[i].strip()
        i += 1
    return text, i


def page_items(page):
    """(line, kind, payload) in page order: ("run", argv) for a command to run
    before later checks, ("check", (block, options, [(line, argv, output)]))."""
    items = []
    lines = open(page, encoding="utf-8").read().split("\n")
    blocks = {b.line: b for b in all_blocks[page]}
    i = 0
    while i < len(lines):
        if lines[i].lstrip().startswith("```") and (i + 2) in blocks:
            b = blocks[i + 2]
            options = b.comment(r"output checked:")
            segments = split_output_block(b)
            if options is not None:
                items.append((b.line, "check", (b, options, segments)))
            else:
                if segments and any(out for _, argv, out in segments if argv):
                    note(f"{b.where}: output block not checked (no <!-- output checked --> marker)")
                for line, argv, _ in segments:
                    if argv:
                        items.append((line, "run", argv))
                if not segments:
                    j = 0
                    while j < len(b.lines):
                        if COMMAND.match(b.lines[j].strip()):
                            text, k = join_continued(b.lines, j)
                            argv = concrete(text)
                            if argv:
                                items.append((b.line + j, "run", argv))
                            j = k
                        else:
                            j += 1
            i = b.line + len(b.lines)
            continue
        if lines[i].startswith("    ") and COMMAND.match(lines[i].strip()):
            text, k = join_continued(lines, i)
            argv = concrete(text)
            if argv:
                items.append((i + 1, "run", argv))
            i = k
            continue
        i += 1
    return items


def split_output_block(b):
    """[(line, argv or None, [(line, output text)])] when the block is a command
    followed by its output (later `$ ` lines start further commands), else []."""
    if not b.lines or not COMMAND.match(b.lines[0].strip()):
        return []
    dollar = b.lines[0].startswith("$ ")
    segments, j = [], 0
    while j < len(b.lines):
        text, k = join_continued(b.lines, j)
        start = j
        output = []
        j = k
        while j < len(b.lines) and not (dollar and b.lines[j].startswith("$ ")):
            output.append((b.line + j, b.lines[j]))
            j += 1
        if not dollar and any(COMMAND.match(l.strip()) or l.lstrip().startswith("#")
                              for _, l in output if l.strip()):
            return []       # several commands (a script), not a command and its output
        segments.append((b.line + start, concrete(text), output))
    if not any(l.strip() for _, _, out in segments for _, l in out):
        return []
    return segments


def skeleton(line):
    return " ".join(NUMBER.sub("#", line).split())


def compare(b, options, segments):
    global output_blocks, numbers_compared
    try:
        opts = dict(w.split("=", 1) for w in shlex.split(options))
        rtol, atol = float(opts.pop("rtol")), float(opts.pop("atol", 0))
        skip = re.compile(opts.pop("skip")) if "skip" in opts else None
        if opts:
            raise ValueError(f"unknown option(s) {', '.join(opts)}")
    except (ValueError, KeyError, re.error) as e:
        fail(b.where, f"bad marker '<!-- output checked: {options} -->' ({e}); "
                      "write rtol=R [atol=A] [skip=REGEX]")
        return
    if not segments:
        fail(b.where, "marked output checked, but it is not a pneumid command followed by output")
        return
    ran = False
    for line, argv, shown in segments:
        where = f"{b.rel}:{line}"
        if argv is None:
            fail(where, "marked output checked, but the command is not one that can be run")
            continue
        try:
            r = subprocess.run([pneumid] + argv[1:], cwd=work, capture_output=True,
                               text=True, timeout=300)
        except subprocess.TimeoutExpired:
            fail(where, "timed out after 300 s")
            continue
        if r.returncode != 0:
            fail(where, f"exit {r.returncode}: {tail(r.stderr, 500)}")
            continue
        keep = lambda text: bool(text.strip()) and not (skip and skip.search(text))
        expected = [(n, l) for n, l in shown if keep(l)]
        actual = [l for l in (r.stdout + r.stderr).split("\n") if keep(l)]
        if len(expected) != len(actual):
            fail(where, f"the page shows {len(expected)} output lines, the command prints "
                        f"{len(actual)}:\n" + "\n".join(actual))
        for (n, e_line), a_line in zip(expected, actual):
            if skeleton(e_line) != skeleton(a_line):
                fail(f"{b.rel}:{n}", f"text differs\n  shown:   {e_line.strip()}\n"
                                     f"  printed: {a_line.strip()}")
                continue
            for e_text, a_text in zip(NUMBER.findall(e_line), NUMBER.findall(a_line)):
                e, a = float(e_text), float(a_text)
                numbers_compared += 1
                if abs(a - e) > atol + rtol * max(abs(a), abs(e)):
                    fail(f"{b.rel}:{n}", f"shown {e_text}, printed {a_text} (rtol {rtol:g}"
                                         + (f", atol {atol:g}" if atol else "") + ")")
        ran = True
    output_blocks += ran


def check_outputs():
    for page in pages:
        items = page_items(page)
        last = max((i for i, (_, kind, _) in enumerate(items) if kind == "check"), default=-1)
        for line, kind, payload in items[:last + 1]:
            if kind == "run":
                r = subprocess.run([pneumid] + payload[1:], cwd=work, capture_output=True,
                                   text=True, timeout=300)
                if r.returncode != 0:
                    note(f"{os.path.relpath(page, src)}:{line}: earlier command exits "
                         f"{r.returncode} (docs_commands_test reports it)")
            else:
                compare(*payload)


# ---------------------------------------------------------------------------
# The C++ compilations run beside the commands and the Python blocks.
# ---------------------------------------------------------------------------
sources = cpp_sources()


def compile_cpp_guarded():
    try:
        compile_cpp(sources)
    except Exception as e:      # report, and let the counts fail the test
        fail("C++", f"{type(e).__name__}: {e}")


cpp_thread = threading.Thread(target=compile_cpp_guarded)
cpp_thread.start()
check_outputs()
python_expected = run_python()
cpp_thread.join()
run_programs()

compiled = cpp_counts["programs"] + cpp_counts["fragments"]
print(f"C++ blocks compiled: {compiled} ({cpp_counts['programs']} programs, "
      f"{cpp_counts['run']} run; {cpp_counts['fragments']} fragments)")
print(f"Python blocks run: {python_count}")
print(f"output blocks checked: {output_blocks}")
print(f"numbers compared: {numbers_compared}")
print(f"time: {time.monotonic() - started:.1f} s", flush=True)
for label, count, minimum in (("C++ blocks compiled", compiled, min_cpp),
                              ("Python blocks run", python_count,
                               min_py if python_expected else 0),
                              ("output blocks checked", output_blocks, min_out),
                              ("numbers compared", numbers_compared, min_numbers)):
    if count < minimum:
        fail("docs", f"{label}: {count}, fewer than the {minimum} expected "
                     "(blocks lost by the parser, or failing)")
sys.exit(1 if failures else 0)
PYEOF
  fail "documented snippets and outputs (see above)"
finish
