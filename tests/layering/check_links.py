#!/usr/bin/env python3
"""Holds the build's links to the layers and each program's link closure to
its table.

Reads the build tree's link_graph.tsv (cmake/LinkGraph.cmake: every target,
its folder and its direct links) and fails on
  1. a link between two of the project's targets that crosses the layers as
     an include may not (check_includes.py's rules, on the targets' folders:
     a settings library linking a component, the deployment linking a
     component, a component linking another outside its allowed list);
  2. a program (a target of apps/) whose closure (every project target it
     links, transitively) differs from PROGRAM_CLOSURES, in either
     direction: a new dependency is a decision, written into the table;
  3. a program of FORBIDDEN_EXTERNAL that reaches one of the libraries
     named there (EGL, OpenGL, assimp, OpenCV for the power-cut process).

Usage: check_links.py BUILD_DIR/link_graph.tsv
       check_links.py --self-test
Exit status 0 when every rule holds, 1 otherwise.
"""
import os
import re
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import check_includes  # noqa: E402  (the layer table and its rules)

# What each program links, transitively, of the project's own targets. The
# settings libraries come with the deployment loader (every process
# validates the whole config file); beyond them, a program links its own
# component and what that component itself needs.
DEPLOYMENT = ["tofguard_deployment", "tofguard_common", "tofguard_lcmtypes", "tofguard_auth",
              "tofguard_camera_settings", "tofguard_discrepancy_settings", "tofguard_estimator_settings",
              "tofguard_intervene_settings", "tofguard_launch_settings", "tofguard_occupant_settings",
              "tofguard_renderer_settings",
              "tofguard_risk_settings", "tofguard_sim_settings", "tofguard_view_settings"]
RENDERER = ["tofguard_renderer", "tofguard_scene_model", "tofguard_robot_model", "tofguard_robot_state"]
PROGRAM_CLOSURES = {
    "tofguard-intervene": DEPLOYMENT + ["tofguard_intervene"],
    "tofguard-reset": DEPLOYMENT + ["tofguard_intervene"],
    # With several cameras tofguard-risk reads the arm's meshes once, for
    # each link's surface area (the arm no camera sees).
    "tofguard-risk": DEPLOYMENT + ["tofguard_risk", "tofguard_robot_model", "tofguard_scene_model"],
    "tofguard-discrepancy": DEPLOYMENT + ["tofguard_discrepancy"],
    "tofguard-renderer": DEPLOYMENT + RENDERER,
    "tofguard-estimator": DEPLOYMENT + RENDERER + ["tofguard_estimator"],
    "tofguard-calibrate-extrinsics": DEPLOYMENT + RENDERER + ["tofguard_estimator"],
    # The camera program runs a USB camera or the simulated one.
    "tofguard-camera": DEPLOYMENT + RENDERER + ["tofguard_camera", "tofguard_uvc_camera", "tofguard_sim_camera"],
    # The simulated arm and the fault injector: no renderer.
    "tofguard-joints-sim": DEPLOYMENT + ["tofguard_sim_arm", "tofguard_robot_model"],
    "tofguard-sim-fault": DEPLOYMENT + ["tofguard_sim_arm", "tofguard_robot_model"],
    "tofguard-launch": DEPLOYMENT + ["tofguard_launch"],
    "tofguard-spy": DEPLOYMENT + ["tofguard_spy"],
    # The viewer colours I_dis as tofguard-discrepancy does and draws the
    # protective field as the risk rules size it.
    "tofguard-view": DEPLOYMENT + ["tofguard_view", "tofguard_discrepancy", "tofguard_risk", "tofguard_robot_model",
                                   "tofguard_scene_model"],
    "tofguard-tune": DEPLOYMENT + RENDERER + ["tofguard_tune", "tofguard_discrepancy", "tofguard_risk"],
    "tofguard-keygen": ["tofguard_auth", "tofguard_common", "tofguard_lcmtypes"],
    "tofguard-calibrate-depth": ["tofguard_calibration_tool", "tofguard_camera", "tofguard_camera_settings",
                                 "tofguard_common", "tofguard_lcmtypes"],
}

# Libraries a program must not reach at all, by name (imported targets and
# plain library names alike): the power cut and its reset run on no
# graphics, mesh or image code.
NO_GRAPHICS = r"(EGL|GLES|(^|[^a-z])GL($|[^a-z])|OpenGL|assimp|opencv)"
FORBIDDEN_EXTERNAL = {
    "tofguard-intervene": NO_GRAPHICS,
    "tofguard-reset": NO_GRAPHICS,
}


def read_graph(path):
    """{target: (kind, folder, [direct links])}"""
    graph = {}
    with open(path, encoding="utf-8") as f:
        for line in f:
            line = line.rstrip("\n")
            if not line:
                continue
            name, kind, folder, links = (line.split("\t") + ["", "", ""])[:4]
            graph[name] = (kind, folder, [link for link in links.split(";") if link])
    return graph


def is_project_target(graph, name):
    return name in graph and graph[name][0] != "IMPORTED" and graph[name][1] != "-"


def closure(graph, name):
    seen, queue = set(), list(graph.get(name, ("", "", []))[2])
    while queue:
        link = queue.pop()
        if link in seen:
            continue
        seen.add(link)
        queue.extend(graph.get(link, ("", "", []))[2])
    return seen


def layer_of_target(graph, name):
    folder = graph[name][1]
    return check_includes.layer_of_file(os.path.join(folder if folder != "." else "cmake", "x.cpp"))


def link_layer_problems(graph):
    problems = []
    for name in sorted(graph):
        if not is_project_target(graph, name):
            continue
        layer, component = layer_of_target(graph, name)
        for link in graph[name][2]:
            if not is_project_target(graph, link):
                continue
            link_layer, link_component = layer_of_target(graph, link)
            problem = check_includes.rule_broken(layer, component, link_layer, link_component)
            if problem:
                problems.append("%s (%s/) links %s (%s/): %s" % (name, graph[name][1], link, graph[link][1], problem))
    return problems


def closure_problems(graph):
    problems = []
    programs = sorted(n for n in graph if graph[n][0] == "EXECUTABLE" and graph[n][1] == "apps")
    for program in programs:
        reached = closure(graph, program)
        own = {t for t in reached if is_project_target(graph, t)}
        if program in PROGRAM_CLOSURES:
            expected = set(PROGRAM_CLOSURES[program])
            for extra in sorted(own - expected):
                problems.append("%s links %s, which its row of PROGRAM_CLOSURES does not name" % (program, extra))
            for missing in sorted(expected - own):
                problems.append("%s no longer links %s: remove it from its row of PROGRAM_CLOSURES" %
                                (program, missing))
        forbidden = FORBIDDEN_EXTERNAL.get(program)
        if forbidden:
            for lib in sorted(reached - own):
                if re.search(forbidden, lib):
                    problems.append("%s reaches %s, which it must not (FORBIDDEN_EXTERNAL)" % (program, lib))
        print("%s: %d project targets, %d libraries: %s" % (program, len(own), len(reached - own),
                                                             " ".join(sorted(own))))
    for program in sorted(set(PROGRAM_CLOSURES) - set(programs)):
        problems.append("%s has a row in PROGRAM_CLOSURES but is no program of apps/" % program)
    return problems


def main(argv):
    if len(argv) != 2:
        print("usage: check_links.py BUILD_DIR/link_graph.tsv | --self-test")
        return 2
    graph = read_graph(argv[1])
    problems = link_layer_problems(graph) + closure_problems(graph)
    for text in problems:
        print("LINK VIOLATION: " + text)
    print("%d targets read, %d violations" % (len(graph), len(problems)))
    return 1 if problems else 0


def self_test():
    """A made-up graph with one bad link per rule; each must be reported."""
    import contextlib
    import io
    import tempfile

    rows = [
        ("tofguard-intervene", "EXECUTABLE", "apps", "tofguard_deployment;tofguard_intervene"),
        ("tofguard-renderer", "EXECUTABLE", "apps", "tofguard_deployment;tofguard_renderer"),
        ("tofguard_deployment", "STATIC_LIBRARY", "deployment", "tofguard_risk_settings;tofguard_renderer"),
        ("tofguard_risk_settings", "STATIC_LIBRARY", "settings", "tofguard_common;tofguard_risk"),
        ("tofguard_intervene", "STATIC_LIBRARY", "intervene", "tofguard_common;tofguard_risk_settings"),
        ("tofguard_renderer", "STATIC_LIBRARY", "renderer", "tofguard_common;PkgConfig::EGL"),
        ("tofguard_risk", "STATIC_LIBRARY", "risk", "tofguard_common;tofguard_discrepancy"),
        ("tofguard_discrepancy", "STATIC_LIBRARY", "discrepancy", "tofguard_common"),
        ("tofguard_common", "STATIC_LIBRARY", "common", "yaml-cpp"),
        ("PkgConfig::EGL", "IMPORTED", "-", ""),
    ]
    expected = [
        "tofguard_deployment (deployment/) links tofguard_renderer",
        "tofguard_risk (risk/) links tofguard_discrepancy",
        "tofguard_risk_settings (settings/) links tofguard_risk",
        "tofguard-intervene links tofguard_renderer, which",
        "tofguard-intervene reaches PkgConfig::EGL",
        "tofguard-renderer no longer links tofguard_robot_state",
    ]
    saved = dict(PROGRAM_CLOSURES)
    PROGRAM_CLOSURES.clear()
    PROGRAM_CLOSURES.update({"tofguard-intervene": ["tofguard_deployment", "tofguard_intervene", "tofguard_common",
                                                     "tofguard_risk_settings", "tofguard_risk",
                                                     "tofguard_discrepancy"],
                             "tofguard-renderer": ["tofguard_deployment", "tofguard_renderer", "tofguard_common",
                                                   "tofguard_risk_settings", "tofguard_risk",
                                                   "tofguard_discrepancy", "tofguard_robot_state"]})
    out = io.StringIO()
    try:
        with tempfile.TemporaryDirectory() as folder:
            path = os.path.join(folder, "link_graph.tsv")
            with open(path, "w") as f:
                f.writelines("\t".join(row) + "\n" for row in rows)
            with contextlib.redirect_stdout(out):
                status = main(["check_links.py", path])
    finally:
        PROGRAM_CLOSURES.clear()
        PROGRAM_CLOSURES.update(saved)
    text = out.getvalue()
    print(text)
    reported = [line for line in text.splitlines() if line.startswith("LINK VIOLATION: ")]
    missed = [e for e in expected if not any(e in line for line in reported)]
    extra = [line for line in reported if not any(e in line for e in expected)]
    for e in missed:
        print("SELF-TEST: not reported: " + e)
    for line in extra:
        print("SELF-TEST: wrongly reported: " + line)
    ok = status == 1 and not missed and not extra
    print("self-test " + ("passed" if ok else "FAILED"))
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(self_test() if sys.argv[1:] == ["--self-test"] else main(sys.argv))
