"""The further round of hostile input of issue 24 (semantics): 54 command lines against the weftsim tree
given, each classified as right, traceback, silent wrong answer, unclear error or hang (docs/hard-cases.md,
round three).  Usage: python scripts/hostile_semantics.py TREE OUTDIR [CASE,CASE...]  (TREE: the directory
holding the weftsim package; 10 to 20 minutes on 2 cores)."""
import csv
import json
import os
import subprocess
import sys
import time
from pathlib import Path

PY = sys.executable
TREE = sys.argv[1]
OUT = Path(sys.argv[2])
OUT.mkdir(parents=True, exist_ok=True)


def summary(d):
    return json.loads((Path(d) / "summary.json").read_text())


def table(d):
    with open(Path(d) / "sweep.csv") as f:
        return list(csv.DictReader(f))


def wearjson(d):
    return json.loads((Path(d) / "wear.json").read_text())


R = "--revolutions"
CASES = [
    # (id, args, kind, words-or-check)  kind: refuse (rc 2), fail (rc 3), ok (rc 0), partial (rc 5)
    ("f-clearance-alone", ["run", "reference", "--set", "joint_f.clearance_mm=0.25", R, "0.05", "--engine", "reference"],
     "ok", lambda d, o, e: summary(d)["scene"]["joint_f.journal_radius_mm"] == 10.0 and "takes" in e),
    ("f-follows-e-pin", ["run", "reference", "--set", "joint_f.clearance_mm=0.25", "--set", "joint_e.journal_radius_mm=5",
                         R, "0.05", "--engine", "reference"],
     "ok", lambda d, o, e: summary(d)["scene"]["joint_f.journal_radius_mm"] == 5.0),
    ("f-follows-law-shorthand", ["run", "reference", "--set", "joint_f.clearance_mm=0.25", "--law", "flores", R, "0.05",
                                 "--engine", "reference"],
     "ok", lambda d, o, e: summary(d)["scene"]["joint_f.law"] == "flores"),
    ("f-clearance-beyond-radius", ["run", "reference", "--set", "joint_f.clearance_mm=4", "--set",
                                   "joint_e.journal_radius_mm=3", R, "0.05"], "refuse",
     ["joint_f.clearance_mm", "journal radius 3 mm"]),
    ("f-law-on-ideal-f", ["run", "reference", "--set", "joint_f.law=hertz", R, "0.05"], "refuse", ["joint_f.law", "ideal"]),
    ("f-rule-on-ideal-f", ["run", "reference", "--set", "joint_f.impact_velocity_rule=onset", R, "0.05"], "refuse",
     ["joint_f.impact_velocity_rule", "ideal"]),
    ("f-bad-law", ["run", "clearance_f", "--set", "joint_f.law=hertz", R, "0.05"], "refuse", ["joint_f.law", "one of"]),
    ("f-friction-exudyn", ["run", "reference", "--set", "joint_f.clearance_mm=0.25", "--set",
                           "joint_f.friction_coefficient=0.1", "--engine", "exudyn", R, "0.05"], "fail",
     ["joint_f.friction_coefficient"]),
    ("f-on-ideal-scene", ["run", "ideal", "--set", "joint_f.clearance_mm=0.25", R, "0.05", "--engine", "reference"],
     "ok", lambda d, o, e: summary(d)["scene"]["joint_f.clearance_mm"] == 0.25),
    # Wear at F exists now (issue 26, part 3): both wear, and wear.json names the joints.
    ("wear-clearance-f", ["wear", "clearance_f", "--hours", "1", "--no-plot"], "ok",
     lambda d, o, e: wearjson(d)["joints"] == ["f"]),
    ("wear-set-f", ["wear", "reference", "--set", "joint_f.clearance_mm=0.25", "--hours", "1", "--no-plot"], "ok",
     lambda d, o, e: wearjson(d)["joints"] == ["e", "f"]),
    ("sweep-f-0-and-loose", ["sweep", "reference", "--vary", "joint_f.clearance_mm=0,0.25", R, "0.1", "--engine", "reference"],
     "ok", lambda d, o, e: [r.get("contact_force_f_N_rev1_peak", "x") == "" for r in table(d)] == [True, False]),
    ("sweep-ef", ["sweep", "clearance_ef", "--vary", "joint_f.clearance_mm=0.1,0.25", R, "0.1", "--engine", "reference"],
     "ok", lambda d, o, e: all(float(r["contact_force_f_N_rev1_peak"]) > 0 and float(r["contact_force_N_rev1_peak"]) > 0
                               for r in table(d))),
    ("sweep-e-key-on-ideal-e", ["sweep", "clearance_f", "--vary", "restitution=0.5,0.9", R, "0.1"], "refuse",
     ["joint_e.restitution", "ideal"]),
    ("sweep-e-key-some-cells", ["sweep", "clearance_f", "--vary", "clearance_mm=0,0.1", "--set", "restitution=0.5", R,
                                "0.1", "--engine", "reference"], "ok", lambda d, o, e: len(table(d)) == 2),
    ("sweep-law-on-ideal", ["sweep", "ideal", "--vary", "law=flores,gonthier", R, "0.1"], "refuse", ["joint_e.law", "ideal"]),
    ("sweep-f-radius-on-ideal-f", ["sweep", "reference", "--vary", "joint_f.journal_radius_mm=5,8", R, "0.1"], "refuse",
     ["joint_f.journal_radius_mm", "ideal"]),
    ("sweep-wear-key", ["sweep", "reference", "--vary", "joint_e.wear.wear_coefficient=1e-7,1e-6", R, "0.1"], "refuse",
     ["joint_e.wear.wear_coefficient", "wear"]),
    ("run-wear-key", ["run", "reference", "--set", "joint_e.wear.wear_coefficient=1e-6", R, "0.05"], "refuse",
     ["joint_e.wear.wear_coefficient", "wear"]),
    ("sweep-both-ideal-cell", ["sweep", "reference", "--vary", "clearance_mm=0,0.25", "--vary", "joint_f.clearance_mm=0,0.25",
                               R, "0.1", "--engine", "reference"],
     "ok", lambda d, o, e: [r["contact_force_N_rev1_peak"] == "" for r in table(d)] == [True, True, False, False]),
    ("list-set-3", ["run", "reference", "--set", "friction_velocities_m_s=1e-4,2e-4,3e-4", R, "0.05"], "refuse",
     ["friction_velocities_m_s", "2 numbers"]),
    ("list-set-ok", ["run", "reference", "--set", "friction_velocities_m_s=1e-4,3e-4", R, "0.05", "--engine", "reference"],
     "ok", lambda d, o, e: summary(d)["scene"]["joint_e.friction_velocities_m_s"] == [1e-4, 3e-4]),
    ("ideal-e-pin", ["run", "reference", "--clearance-mm", "0", "--set", "joint_e.journal_radius_mm=5", R, "0.05"], "refuse",
     ["joint_e.journal_radius_mm", "ideal"]),
    ("compare-f-short", ["compare", "clearance_f", R, "0.5"], "partial", ["partial"]),
    ("compare-ideal-short", ["compare", "ideal", R, "0.5"], "ok", lambda d, o, e: "AGREE" in o),
    ("compare-0.99", ["compare", "reference", R, "0.99"], "partial", ["partial", "--revolutions 1"]),
    ("animate-ef", ["animate", "clearance_ef", R, "0.3", "--frames", "4", "--engine", "reference", "-o", "{dir}/a.gif"],
     "ok", lambda d, o, e: "at E, c = 0.25 mm at F" in o and float(o.split("within ")[1].split()[0]) < 1e-9),
    ("animate-set-f", ["animate", "reference", "--set", "joint_f.clearance_mm=0.25", R, "0.3", "--frames", "4",
                       "--engine", "reference", "-o", "{dir}/a.gif"], "ok", lambda d, o, e: "takes" in e and "at F" in o),
    ("wear-hours-huge", ["wear", "reference", "--hours", "1e7"], "refuse", ["--hours"]),
    ("wear-hours-1e308", ["wear", "reference", "--hours", "1e308"], "refuse", ["--hours"]),
    ("wear-hours-tiny", ["wear", "reference", "--hours", "1e-9", "--no-plot"], "ok",
     lambda d, o, e: wearjson(d)["complete"]),
    ("wear-k-0.9", ["wear", "reference", "--set", "joint_e.wear.wear_coefficient=0.9", "--hours", "1"], "refuse",
     ["joint_e.wear.wear_coefficient"]),
    ("wear-h-subnormal", ["wear", "reference", "--set", "joint_e.wear.journal_hardness_mpa=1e-310", "--hours", "1"],
     "refuse", ["joint_e.wear.journal_hardness_mpa"]),
    ("wear-k-max-h-min", ["wear", "reference", "--set", "joint_e.wear.wear_coefficient=1e-2", "--set",
                          "joint_e.wear.bearing_hardness_mpa=1", "--hours", "1", "--no-plot"], "fail", ["too fast"]),
    ("wear-slope-limit", ["wear", "reference", "--set", "joint_e.journal_radius_mm=3", "--set",
                          "joint_e.wear.wear_coefficient=1e-4", "--hours", "1e5", "--no-plot"], "ok",
     lambda d, o, e: wearjson(d)["ended"] and "ends at" in o and wearjson(d)["final_effective_clearance_e_mm"] < 3),
    ("wear-limit-beyond-radius", ["wear", "reference", "--limit-clearance-mm", "100", "--hours", "1"], "refuse",
     ["--limit-clearance-mm", "journal radius"]),
    ("wear-1mm-journal", ["wear", "reference", "--set", "joint_e.journal_radius_mm=1", "--hours", "100", "--no-plot"],
     "fail", ["penetration", "[joint_e]"]),
    ("wear-profile-8", ["wear", "reference", "--set", "joint_e.wear.profile_points=8", "--hours", "5", "--no-plot"],
     "refuse", ["joint_e.wear.profile_points", ">= 180"]),
]

CASES += [
    ("r2-ef-f-zero", ["run", "clearance_ef", "--set", "joint_f.clearance_mm=0", R, "0.05", "--engine", "reference"], "ok",
     lambda d, o, e: summary(d)["scene"]["joint_f.clearance_mm"] == 0 and "takes" not in e),
    ("r2-f-radius-below-clearance", ["run", "reference", "--set", "joint_f.clearance_mm=0.25", "--set",
                                     "joint_f.journal_radius_mm=0.2", R, "0.05"], "refuse", ["joint_f.clearance_mm", "journal radius"]),
    ("r2-sets-make-clearance-f", ["run", "reference", "--clearance-mm", "0", "--set", "joint_f.clearance_mm=0.25", R, "0.05",
                                  "--engine", "reference"], "ok",
     lambda d, o, e: summary(d)["scene"]["joint_f.law"] == "variable_kd" and "takes" in e),
    ("r2-ideal-restitution", ["run", "ideal", "--set", "joint_e.restitution=0.5", R, "0.05"], "refuse",
     ["joint_e.restitution", "ideal"]),
    ("r2-sweep-law-some-cells", ["sweep", "reference", "--vary", "clearance_mm=0,0.25", "--vary", "law=flores,variable_kd",
                                 R, "0.1", "--engine", "reference"], "ok", lambda d, o, e: len(table(d)) == 4),
    ("r2-sweep-f-law", ["sweep", "clearance_f", "--vary", "joint_f.law=flores,variable_kd", R, "0.1", "--engine", "reference"],
     "ok", lambda d, o, e: all(float(r["contact_force_f_N_rev1_peak"]) > 0 for r in table(d))),
    ("r2-sweep-e-ideal-every-cell", ["sweep", "reference", "--vary", "joint_f.clearance_mm=0.1,0.25", "--set",
                                     "joint_e.clearance_mm=0", "--set", "restitution=0.5", R, "0.1"], "refuse",
     ["joint_e.restitution", "ideal"]),
    ("r2-tree-with-f", ["run", "reference", "--set", "joint_f.clearance_mm=0.25", "--engine", "exudyn", "--set",
                        "solver.exudyn.model=kinematic_tree", R, "0.05"], "fail", ["solver.exudyn.model"]),
    ("r2-scipy-with-f", ["run", "reference", "--set", "joint_f.clearance_mm=0.25", "--set", "solver.reference.method=DOP853",
                         R, "0.05", "--engine", "reference"], "fail", ["solver.reference.method"]),
    ("r2-animate-ideal", ["animate", "ideal", R, "0.3", "--frames", "4", "--engine", "reference", "-o", "{dir}/a.gif"],
     "ok", lambda d, o, e: "ideal joints at E and F" in o),
    ("r2-wear-clearance-near-radius", ["wear", "reference", "--set", "joint_e.clearance_mm=4.9", "--set",
                                       "joint_e.journal_radius_mm=5", "--hours", "10", "--no-plot"], "ok",
     lambda d, o, e: "ends at" in o or wearjson(d)["complete"]),
    ("r2-wear-1e6-hours", ["wear", "reference", "--hours", "1e6", "--no-plot"], "ok",
     lambda d, o, e: wearjson(d)["ended"] and "ends at" in o),
    ("r2-wear-1p5mm-journal", ["wear", "reference", "--set", "joint_e.journal_radius_mm=1.5", "--hours", "1e4", "--no-plot"],
     "ok", lambda d, o, e: wearjson(d)["ended"] or wearjson(d)["complete"]),
    ("r2-wear-one-rev-updates", ["wear", "reference", "--set", "joint_e.wear.revolutions_per_update=1", "--set",
                                 "joint_e.wear.settle_revolutions=0", "--hours", "5", "--no-plot"], "ok",
     lambda d, o, e: wearjson(d)["complete"]),
    ("r2-wear-f-half", ["wear", "reference", "--set", "joint_e.wear.max_clearance_change=0.5", "--hours", "100",
                        "--no-plot"], "ok", lambda d, o, e: wearjson(d)["complete"] or wearjson(d)["ended"]),
    ("r2-compare-f-set-1rev", ["compare", "reference", "--set", "joint_f.clearance_mm=0.25", R, "1"], "ok",
     lambda d, o, e: "contact_force_f_N" in o and ("AGREE" in o or "DISAGREE" in o)),
]


def classify(case, rc, out, err, elapsed, directory):
    name, args, kind, expect = case
    if rc is None:
        return "hang"
    if "Traceback" in err or rc not in (0, 2, 3, 4, 5, 130):
        return "traceback"
    lines = [l for l in err.splitlines() if "error:" in l]
    if kind in ("refuse", "fail", "partial"):
        want = {"refuse": 2, "fail": 3, "partial": 5}[kind]
        if rc == 0:
            return "silent wrong answer"
        if rc != want or len(lines) != 1 or not all(w in lines[0] for w in expect):
            return "unclear error"
        return "right"
    if rc == 4 and args[0] == "compare":  # engines that disagree, said so: the check decides
        rc = 0
    if rc not in (0,):
        return "unclear error" if rc == 2 else "failed run"
    try:
        good = expect(directory, out, err)
    except Exception:  # noqa: BLE001 - a missing or malformed output file is a wrong answer too
        good = False
    return "right" if good else "silent wrong answer"


results = []
ONLY = set(sys.argv[3].split(",")) if len(sys.argv) > 3 else None
for case in CASES:
    name, args, kind, expect = case
    if ONLY and name not in ONLY:
        continue
    directory = OUT / name
    if "-o" not in args:
        args = args + ["-o", str(directory)]
    args = [a.replace("{dir}", str(directory)) for a in args]
    env = dict(os.environ, PYTHONPATH=TREE)
    start = time.time()
    try:
        done = subprocess.run([PY, "-m", "weftsim.cli", *args], capture_output=True, text=True, timeout=120, env=env,
                              cwd=OUT)
        rc, out, err = done.returncode, done.stdout, done.stderr
    except subprocess.TimeoutExpired:
        rc, out, err = None, "", ""
    verdict = classify(case, rc, out, err, time.time() - start, directory)
    last = [l for l in err.strip().splitlines() if l][-1:] or [""]
    results.append((name, verdict, rc, last[0][:230]))
    print(f"{verdict:22s} rc={rc} {name}: {last[0][:230]}", flush=True)

counts = {}
for _, verdict, _, _ in results:
    counts[verdict] = counts.get(verdict, 0) + 1
print(len(results), "cases:", counts)
