#!/usr/bin/env python3
"""Fails on an #include that crosses tofguard's layers upwards or sideways,
or reaches into another folder's src/, and on a main() outside the programs'
floor (apps/).

Layers, bottom to top (docs/architecture.md, "Layout and layers"):

  lcmtypes      generated wire types, included as "tofguard/<name>_t.hpp"
  common        "tofguard/common/..."
  auth          message authentication (may include common)
  robot_model   the URDF's kinematic tree and geometry
  robot_state   joint and camera-pose histories (may include robot_model)
  settings      each component's settings and their readers,
                "tofguard/settings/..." (settings/)
  components    camera, renderer, sim, discrepancy, risk, estimator,
                intervene, launch, spy, view, tune: each may include the layers
                below and the components in ALLOWED_COMPONENT_DEPENDENCIES
  deployment    the config loader (every section, through the settings) and
                the process runner: beside the components, never including
                one nor included by one
  top           apps/: every program's main(), the tools and their engines;
                anything but tests/ (and auth/examples/, the controllers'
                examples, which stand alone)

tests/ may include anything. Nobody writes "../" in an include, nor reaches
into another folder's src/ (through a path or a bare name that only an
include path finds). No file outside apps/, tests/ and examples/ folders
defines main() (or BENCHMARK_MAIN).

The same rules hold for the links between the build's targets
(check_links.py, on the build tree's link_graph.tsv).

Usage: check_includes.py [REPO_ROOT]   (default: two folders up from here)
       check_includes.py --self-test   (the rules on a small made-up tree)
Exit status 0 when every include keeps the rules (known violations in
KNOWN_VIOLATIONS are listed but allowed), 1 otherwise. A folder that does
not exist is simply not scanned.
"""
import fnmatch
import os
import re
import sys

# Rank of each layer: a folder may include its own layer's headers only as
# the component rules allow, and any lower rank; two different layers of
# the same rank (the components and the deployment) include nothing of
# each other.
LAYER_RANK = {
    "lcmtypes": 0,
    "common": 1,
    "robot_model": 2,
    "auth": 2,
    "robot_state": 2,
    "settings": 3,
    "component": 4,
    "deployment": 4,
    "top": 5,
}

COMPONENTS = ["camera", "renderer", "sim", "discrepancy", "risk", "estimator", "intervene", "launch", "spy", "view",
              "tune"]

# Which other components a component may include. Everything not listed
# here is a dependency running sideways and must go through a message or a
# lower layer instead.
ALLOWED_COMPONENT_DEPENDENCIES = {
    "camera": [],
    "renderer": [],
    "sim": ["camera", "renderer"],  # the simulated camera renders the model as a real camera would see it
    "discrepancy": [],
    "risk": [],
    "estimator": ["renderer"],  # the estimator renders candidate poses
    "intervene": [],
    "launch": [],
    "spy": [],
    "view": ["discrepancy"],  # the viewer colours I_dis as tofguard-discrepancy does
    # tofguard-tune judges a recording as the chain does: renders it, compares it,
    # runs the sequential tests on it
    "tune": ["renderer", "discrepancy", "risk"],
}

# Within robot_model / robot_state: robot_state may include robot_model,
# not the other way round.
ALLOWED_SAME_LAYER = {
    "robot_state": ["robot_model"],
    "robot_model": [],
    "auth": [],
}

# Includes that break a rule today, each with why it is allowed for now.
# Each entry: (including file, fnmatch pattern relative to the repository
# root; included header as written; why). An entry that no longer matches
# anything is reported as stale.
KNOWN_VIOLATIONS = []
SKIP_DIRS = {".git", "node_modules", "__pycache__"}
INCLUDE = re.compile(r'^\s*#\s*include\s*([<"])([^">]+)[">]')
# A program's entry point: main() or Google Benchmark's BENCHMARK_MAIN().
ENTRY_POINT = re.compile(r'^\s*(int\s+main\s*\(|BENCHMARK_MAIN\s*\()')


def is_build_dir(path):
    return os.path.exists(os.path.join(path, "CMakeCache.txt"))


def source_files(root):
    for folder, dirs, files in os.walk(root):
        dirs[:] = sorted(d for d in dirs if d not in SKIP_DIRS and not d.startswith(".")
                         and not is_build_dir(os.path.join(folder, d)))
        for name in sorted(files):
            if name.endswith((".cpp", ".hpp", ".h", ".cc")):
                yield os.path.relpath(os.path.join(folder, name), root)


def layer_of_file(rel):
    """(layer, component) of a file of the tree, by its folder."""
    parts = rel.split(os.sep)
    top = parts[0]
    if top == "tests":
        return ("tests", None)
    if top == "apps" or (len(parts) >= 2 and parts[1] == "examples"):
        return ("top", top)
    if top in ("lcmtypes", "common", "auth", "robot_model", "robot_state", "settings", "deployment"):
        return (top, top)
    if top in COMPONENTS:
        return ("component", top)
    return ("top", top)  # anything else at the top (cmake/, scripts)


def layer_of_header(header):
    """(layer, component) a "tofguard/..." header belongs to, or None."""
    parts = header.split("/")
    if parts[0] != "tofguard" or len(parts) < 2:
        return None
    if len(parts) == 2:
        return ("lcmtypes", "lcmtypes")  # tofguard/<type>_t.hpp, generated
    name = parts[1]
    if name in ("common", "auth", "robot_model", "robot_state", "settings", "deployment"):
        return (name, name)
    if name in COMPONENTS:
        return ("component", name)
    return ("unknown", name)


def rule_broken(file_layer, file_component, header_layer, header_component):
    """None when the include keeps the layering, else which rule it breaks."""
    if file_layer in ("tests", "top"):
        return None
    if header_layer == "unknown":
        return "'tofguard/%s/' is no folder of the layer table" % header_component
    if header_component == file_component:
        return None
    rank, header_rank = LAYER_RANK[file_layer], LAYER_RANK[header_layer]
    if header_rank < rank:
        return None
    if header_rank > rank:
        return "%s (layer %s) may not include the higher layer %s" % (file_component, file_layer, header_layer)
    if header_layer != file_layer and "deployment" in (file_layer, header_layer):
        return "%s (layer %s) may not include %s (layer %s) beside it" % (file_component, file_layer,
                                                                          header_component, header_layer)
    if file_layer == "component":
        allowed = ALLOWED_COMPONENT_DEPENDENCIES.get(file_component, [])
        if header_component in allowed:
            return None
        if not allowed:
            return "component %s may include no other component" % file_component
        return "component %s may include only %s of the other components" % (file_component, ", ".join(allowed))
    if header_component in ALLOWED_SAME_LAYER.get(file_component, []):
        return None
    return "%s may not include %s (same layer)" % (file_component, header_component)


def reaches_into_src(root, rel, include):
    """Rule 2: '../', another folder's src/ by path, or a bare name that is
    not beside the including file (so an include path finds it in some
    src/ folder). Returns the broken rule or None."""
    if "../" in include or include.startswith(".."):
        return 'a "../" include: write it as tofguard/<component>/<file>.hpp'
    top = rel.split(os.sep)[0]
    segments = include.split("/")
    if "src" in segments[:-1]:
        owner = segments[0] if segments[0] != "src" else top
        if owner != top:
            return "reaches into %s/src/" % owner
    if include.startswith("tofguard/"):
        return None
    if os.path.exists(os.path.join(root, os.path.dirname(rel), include)):
        return None  # beside the file: a private header of the same folder
    for candidate_top in sorted(os.listdir(root)):
        src = os.path.join(root, candidate_top, "src", include)
        if candidate_top != top and os.path.exists(src):
            return "bare include of %s/src/%s (found through an include path)" % (candidate_top, include)
    return None


def known(rel, include):
    for pattern, header, _why in KNOWN_VIOLATIONS:
        if header == include and fnmatch.fnmatch(rel, pattern):
            return (pattern, header)
    return None


def main(argv):
    root = os.path.abspath(argv[1] if len(argv) > 1 else os.path.join(os.path.dirname(__file__), "..", ".."))
    violations, allowed, used = [], [], set()
    scanned = 0
    for rel in source_files(root):
        scanned += 1
        file_layer, file_component = layer_of_file(rel)
        with open(os.path.join(root, rel), encoding="utf-8", errors="replace") as f:
            for number, line in enumerate(f, 1):
                if file_layer not in ("top", "tests") and ENTRY_POINT.match(line):
                    violations.append("%s:%d: a program's main() in %s/: programs live in apps/" %
                                      (rel, number, rel.split(os.sep)[0]))
                    continue
                m = INCLUDE.match(line)
                if not m:
                    continue
                include = m.group(2).strip()
                problem = reaches_into_src(root, rel, include)
                if problem is None:
                    header = layer_of_header(include)
                    if header is not None:
                        problem = rule_broken(file_layer, file_component, header[0], header[1])
                if problem is None:
                    continue
                text = '%s:%d: #include "%s": %s' % (rel, number, include, problem)
                entry = known(rel, include)
                if entry:
                    used.add(entry)
                    allowed.append(text)
                else:
                    violations.append(text)
    for text in allowed:
        print("known, allowed for now (see KNOWN_VIOLATIONS): " + text)
    for pattern, header, why in KNOWN_VIOLATIONS:
        if (pattern, header) not in used:
            print('stale KNOWN_VIOLATIONS entry, remove it: %s -> "%s" (%s)' % (pattern, header, why))
    for text in violations:
        print("LAYERING VIOLATION: " + text)
    print("%d files scanned, %d violations, %d known" % (scanned, len(violations), len(allowed)))
    return 1 if violations else 0


def self_test():
    """Runs the check on a made-up tree with one include per rule; each bad
    one must be reported and each good one must pass."""
    import contextlib
    import io
    import tempfile

    files = {
        "common/src/a.cpp": ['"tofguard/common/a.hpp"', '"tofguard/depth_image_t.hpp"'],
        "robot_state/src/s.cpp": ['"tofguard/robot_model/m.hpp"'],
        "settings/src/r.cpp": ['"tofguard/settings/s.hpp"', '"tofguard/auth/a.hpp"'],
        "sim/src/s.cpp": ['"tofguard/renderer/r.hpp"', '"tofguard/camera/c.hpp"', '"private.hpp"'],
        "sim/src/private.hpp": [],
        "renderer/src/r.cpp": ['"tofguard/renderer/r.hpp"', '"tofguard/settings/r.hpp"'],
        "apps/tofguard-renderer.cpp": ['"tofguard/deployment/d.hpp"', '"tofguard/sim/s.hpp"'],
        "deployment/src/d.cpp": ['"tofguard/settings/r.hpp"'],
        "auth/examples/e.cpp": ['"tofguard/auth/a.hpp"'],
        "tests/x_test.cpp": ['"tofguard/risk/r.hpp"', '"tool_support.hpp"'],
        # Bad, one per rule:
        "common/src/b.cpp": ['"tofguard/renderer/r.hpp"'],
        "robot_model/src/m.cpp": ['"tofguard/robot_state/s.hpp"'],
        "risk/src/r.cpp": ['"tofguard/renderer/r.hpp"', '"../common/src/x.hpp"', '"robot_tree.hpp"'],
        "risk/include/tofguard/risk/r.hpp": ['"tofguard/deployment/d.hpp"'],
        "settings/src/s.cpp": ['"tofguard/risk/r.hpp"'],
        "deployment/src/e.cpp": ['"tofguard/renderer/r.hpp"'],
        "renderer/src/robot_tree.hpp": [],
        "view/src/v.cpp": ['"renderer/src/r.hpp"', '"tofguard/nowhere/n.hpp"'],
    }
    # main() outside apps/ (written as an include-less line below).
    entry_points = {"renderer/main.cpp": "int main(int argc, char** argv) {", "apps/tofguard-x.cpp": "int main() {",
                    "tests/t.cpp": "int main() {", "auth/examples/e.cpp": "int main() {"}
    expected_bad = {
        ("common/src/b.cpp", "tofguard/renderer/r.hpp"),
        ("robot_model/src/m.cpp", "tofguard/robot_state/s.hpp"),
        ("risk/src/r.cpp", "tofguard/renderer/r.hpp"),
        ("risk/src/r.cpp", "../common/src/x.hpp"),
        ("risk/src/r.cpp", "robot_tree.hpp"),
        ("risk/include/tofguard/risk/r.hpp", "tofguard/deployment/d.hpp"),
        ("settings/src/s.cpp", "tofguard/risk/r.hpp"),
        ("deployment/src/e.cpp", "tofguard/renderer/r.hpp"),
        ("view/src/v.cpp", "renderer/src/r.hpp"),
        ("view/src/v.cpp", "tofguard/nowhere/n.hpp"),
    }
    expected_entry_points = {"renderer/main.cpp"}
    with tempfile.TemporaryDirectory() as root:
        for rel, includes in files.items():
            os.makedirs(os.path.join(root, os.path.dirname(rel)), exist_ok=True)
            with open(os.path.join(root, rel), "w") as f:
                f.writelines("#include %s\n" % i for i in includes)
        for rel, line in entry_points.items():
            os.makedirs(os.path.join(root, os.path.dirname(rel)), exist_ok=True)
            with open(os.path.join(root, rel), "a") as f:
                f.write(line + "\n")
        out = io.StringIO()
        saved = list(KNOWN_VIOLATIONS)
        KNOWN_VIOLATIONS.clear()
        try:
            with contextlib.redirect_stdout(out):
                status = main(["check_includes.py", root])
        finally:
            KNOWN_VIOLATIONS.extend(saved)
    found = set(re.findall(r'LAYERING VIOLATION: (\S+):\d+: #include "([^"]+)"', out.getvalue()))
    found_entry_points = set(re.findall(r"LAYERING VIOLATION: (\S+):\d+: a program's main\(\)", out.getvalue()))
    ok = status == 1 and found == expected_bad and found_entry_points == expected_entry_points
    for wrong in sorted(found_entry_points ^ expected_entry_points):
        print("SELF-TEST: main() wrongly judged: %s" % wrong)
    print(out.getvalue())
    for missed in sorted(expected_bad - found):
        print("SELF-TEST: not reported: %s -> %s" % missed)
    for extra in sorted(found - expected_bad):
        print("SELF-TEST: wrongly reported: %s -> %s" % extra)
    print("self-test " + ("passed" if ok else "FAILED"))
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(self_test() if sys.argv[1:] == ["--self-test"] else main(sys.argv))
