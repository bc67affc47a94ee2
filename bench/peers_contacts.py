#!/usr/bin/python3
"""Contact scenes: the peers (Bullet, MuJoCo) beside lcsim, and issue 26's targets.

Everything runs through the lcsim program (its --json outputs), in one script,
so every ratio compares runs made on the same machine at the same time:

1. table: on the dropped box, the tipped box and the quadruped drop at a few
   amplitudes, lcsim's reported linearisation error (`simulate`) beside each
   peer's final-state difference and first-impact shift to the exact run
   (`compare --peer ...`, h = 1e-3); then the same on the scenes of several
   bodies (`bodies:`): a ball dropped onto a table, the gripper closing on
   the box (h = 1e-3) and the Vision 60 drop (h = 1e-4: its dampers are
   explicit torques in both peers, unstable at 1e-3);
2. the quadruped drop to T = 1 s with the exact method (target < 5 ms wall):
   median of REPEAT runs;
3. Moreau-Jean at h = 1e-3 per step vs MuJoCo's mj_step on the same robot,
   side by side in one program (build/bench/peer_mujoco_step: Moreau-Jean's
   per-step cost from runs to T and 2T, MuJoCo's mj_step timed alone);
4. the exact method's cost per event with 4, 16 and 64 contact points: a box
   (robots/box.urdf) with explicit points on its bottom face (2x2, 4x4, 8x8),
   dropped flat, wall time / events, median of REPEAT runs;
5. friction (issue 27 item 6): the box sliding at the headings 0, pi/8, pi/4
   (mu = 0.3, 1 m/s) in lcsim's exact method (d = 4, 16), Moreau-Jean,
   Bullet (cone, box, one-direction) and MuJoCo (pyramidal, elliptic)
   beside the closed forms, from one run of build/bench/peer_friction_slide
   (docs/contacts.md, "Friction in the peers").

Timings are given as the minimum (the quietest repetition: the machine is
shared) and the median of REPEAT runs.

Usage: bench/peers_contacts.py [path/to/lcsim] [REPEAT]
"""
import json
import os
import statistics
import subprocess
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
ROBOTS = os.path.join(HERE, "..", "robots")
LCSIM = sys.argv[1] if len(sys.argv) > 1 else os.path.join(HERE, "..", "build", "lcsim")
REPEAT = int(sys.argv[2]) if len(sys.argv) > 2 else 7


def run(*args):
    out = subprocess.run([LCSIM, *args], capture_output=True, text=True)
    if out.returncode != 0:
        raise RuntimeError(f"lcsim {' '.join(args)}: exit {out.returncode}: {out.stderr.strip()}")
    return json.loads(out.stdout)


def x0_of(q, n):
    return ",".join(str(v) for v in list(q) + [0.0] * n)


def first_shift(c):
    shifts = [s["shift"] for s in c["event_shifts"] if s["kind"] == "activation" and s["shift"] is not None]
    return shifts[0] if shifts else float("nan")


def table():
    cases = []
    for height in (0.01, 0.05, 0.2):  # the box dropped flat from `height` m
        cases.append(("box_drop", f"drop {height} m", x0_of([0, 0, 0.05 + height, 0, 0, 0], 6)))
    for theta in (0.02, 0.05, 0.1, 0.2):  # the box tipped on an edge by theta rad
        cases.append(("box_tip", f"tip {theta} rad", x0_of([0, 0, 0.05 + 0.1 * theta, theta, 0, 0], 6)))
    for height in (0.01, 0.03):
        cases.append(("quadruped_drop", f"drop {height} m", x0_of([0, 0, 0.35 + height] + [0] * 11, 14)))
    print("scene            amplitude      lin. error   bullet final  bullet shift  mujoco final  mujoco shift")
    for scene, label, x0 in cases:
        path = os.path.join(ROBOTS, scene + "_scene.yaml")
        sim = run("simulate", path, "--x0", x0, "--json", "--dt-out", "0")
        cells = []
        for peer in ("bullet", "mujoco"):
            c = run("compare", path, "--x0", x0, "--peer", peer, "--h", "1e-3", "--json")
            cells += [c["error_final"], first_shift(c)]
        print(f"{scene:16s} {label:14s} {sim['linearisation_error']:.3e}    "
              + "  ".join(f"{v:+.3e}  " for v in cells))
    print("(lin. error: simulate's relative error of the linear model's M and forces over the "
          "run; final: max-abs final-state difference to the exact run; shift: the first "
          "impact's t_peer - t_exact, s)")


def table_bodies():
    data = os.path.join(HERE, "..", "tests", "bullet", "data")
    cases = [(os.path.join(data, "ball_table_scene.yaml"), "ball_table", "1e-3"),
             (os.path.join(ROBOTS, "gripper_box_scene.yaml"), "gripper_box", "1e-3"),
             (os.path.join(ROBOTS, "vision60_drop_scene.yaml"), "vision60_drop", "1e-4")]
    print("scene of bodies  h              lin. error   bullet final  bullet shift  mujoco final  mujoco shift")
    for path, scene, h in cases:
        sim = run("simulate", path, "--json", "--dt-out", "0")
        cells = []
        for peer in ("bullet", "mujoco"):
            c = run("compare", path, "--peer", peer, "--h", h, "--json")
            cells += [c["error_final"], first_shift(c)]
        print(f"{scene:16s} {h:14s} {sim['linearisation_error']:.3e}    "
              + "  ".join(f"{v:+.3e}  " for v in cells))


def walls(*args):
    return sorted(run(*args)["wall_time_s"] for _ in range(REPEAT))


def target_quadruped():
    path = os.path.join(ROBOTS, "quadruped_drop_scene.yaml")
    w = walls("simulate", path, "--json", "--t-end", "1", "--dt-out", "0", "--no-progress")
    best, med = w[0], statistics.median(w)
    print(f"quadruped drop, exact method, T = 1 s: wall min {best * 1e3:.3f} ms, median {med * 1e3:.3f} ms "
          f"over {REPEAT} runs (target < 5 ms: "
          f"{'met' if best < 5e-3 else 'MISSED by %.2f ms' % ((best - 5e-3) * 1e3)} at the minimum, "
          f"{'met' if med < 5e-3 else 'missed'} at the median)")


def target_moreau_jean_vs_mujoco():
    prog = os.path.join(os.path.dirname(LCSIM), "bench", "peer_mujoco_step")
    path = os.path.join(ROBOTS, "quadruped_drop_scene.yaml")
    out = subprocess.run([prog, path, "1e-3", "1", str(REPEAT)], capture_output=True, text=True)
    if out.returncode != 0:
        print(f"peer_mujoco_step failed (exit {out.returncode}): {out.stderr.strip()}")
        return
    r = json.loads(out.stdout)
    print(f"quadruped, h = 1e-3, per step (min of {REPEAT}): moreau-jean {r['moreau_jean_per_step_s'] * 1e6:.2f} us, "
          f"{r['mujoco']} mj_step {r['mj_step_per_step_s'] * 1e6:.2f} us, ratio moreau-jean / MuJoCo = "
          f"{r['ratio']:.2f} (target <= 1)")


def points_scene(n, folder):
    pts = [[-0.15 + 0.3 * i / (n - 1), -0.1 + 0.2 * j / (n - 1), -0.05] for i in range(n) for j in range(n)]
    text = f"""name: box_points_{n * n}
urdf: {os.path.join(ROBOTS, 'box.urdf')}
base: {{type: floating, pose: {{xyz: [0, 0, 0.05]}}}}
planes:
  - {{name: floor, point: [0, 0, 0], normal: [0, 0, 1]}}
contacts:
  - {{link: box, plane: floor, points: {json.dumps(pts)}}}
initial:
  q: {{box.z: 0.25}}
t_end: 0.5
"""
    path = os.path.join(folder, f"box_points_{n * n}.yaml")
    with open(path, "w") as f:
        f.write(text)
    return path


def target_events_per_contacts():
    with tempfile.TemporaryDirectory() as folder:
        print("exact method, box dropped flat on k explicit points (one impact, then rest):")
        base = None
        for n in (2, 4, 8):
            path = points_scene(n, folder)
            runs = [run("simulate", path, "--json", "--dt-out", "0", "--no-progress") for _ in range(REPEAT)]
            wall = min(r["wall_time_s"] for r in runs)
            events = max(1, len(runs[0]["events"]))
            cost = wall / events
            base = base or cost / (n * n)
            print(f"  k = {n * n:3d}: {events} events, LCP solves {runs[0]['lcp_solves']}, "
                  f"wall (min) {wall * 1e3:.3f} ms, per event {cost * 1e3:.3f} ms, "
                  f"per event / k relative to k = 4: {cost / (n * n) / base:.2f}")


def friction_slide():
    prog = os.path.join(os.path.dirname(LCSIM), "bench", "peer_friction_slide")
    out = subprocess.run([prog, "1e-3"], capture_output=True, text=True)
    if out.returncode != 0:
        print(f"peer_friction_slide failed (exit {out.returncode}): {out.stderr.strip()}")
        return
    print(out.stdout, end="")


if __name__ == "__main__":
    table()
    table_bodies()
    print()
    target_quadruped()
    target_moreau_jean_vs_mujoco()
    target_events_per_contacts()
    print()
    friction_slide()
