#!/usr/bin/env python3
"""Writes the long chain of docs/contacts.md ("Public robots tried"): N links
in a row along x (0.05 m apart), a sphere of radius 0.02 m on each, joints
alternating about z and y (limits +-0.5 rad, each a PD spring), a floating
base 1 cm above the floor, spinning about z at 0.5 rad/s.

    robots/generate_chain.py OUT_DIR [N]     # N links (default 80)

writes OUT_DIR/chain.urdf and OUT_DIR/chain_scene.yaml (not shipped: at N =
80 every contact lands at once, t = sqrt(2 * 0.01 / 9.81) = 0.045152 s, on
80 contacts of rank 41, whose mode selection the exact method solves in
scaled time, its levels' scale passing the double range; see
docs/contacts.md). Run it with `lcsim analyze OUT_DIR/chain_scene.yaml`
or `lcsim simulate --method event|moreau-jean ...`.
"""
import os
import sys

INERTIAL = ('<inertial><mass value="{m}"/><inertia ixx="{i}" ixy="0" ixz="0" iyy="{i}" '
            'iyz="0" izz="{i}"/></inertial>')
SPHERE = '<collision><geometry><sphere radius="0.02"/></geometry></collision>'


def urdf(n):
    out = ['<robot name="chain">']
    for k in range(n):
        mass, inertia = ("1", "0.01") if k == 0 else ("0.2", "0.001")
        out.append(f'<link name="l{k}">' + INERTIAL.format(m=mass, i=inertia) + SPHERE + "</link>")
        if k > 0:
            axis = "0 0 1" if k % 2 else "0 1 0"
            out.append(f'<joint name="j{k}" type="revolute"><parent link="l{k - 1}"/>'
                       f'<child link="l{k}"/><origin xyz="0.05 0 0"/><axis xyz="{axis}"/>'
                       '<limit lower="-0.5" upper="0.5" effort="1" velocity="1"/></joint>')
    out.append("</robot>")
    return "\n".join(out) + "\n"


def scene(n):
    joints = ", ".join(f"j{k}" for k in range(1, n))
    lines = [
        "urdf: chain.urdf",
        "base: {type: floating, pose: {xyz: [0, 0, 0.02]}}",
        f"joints: [{joints}]",
        "planes: [{name: floor, normal: [0, 0, 1]}]",
        "contacts:",
    ]
    lines += [f"  - {{link: l{k}, plane: floor}}" for k in range(n)]
    lines.append("springs:")
    lines += [f"  - {{name: k{k}, joint: j{k}, stiffness: 5, damping: 0.1}}" for k in range(1, n)]
    lines += ["initial: {q: {chain.z: 0.03}, v: {chain.rz: 0.5}}", "t_end: 0.2"]
    return "\n".join(lines) + "\n"


def main():
    if len(sys.argv) not in (2, 3):
        sys.exit(__doc__)
    out, n = sys.argv[1], int(sys.argv[2]) if len(sys.argv) == 3 else 80
    if n < 2:
        sys.exit("N must be at least 2")
    os.makedirs(out, exist_ok=True)
    with open(os.path.join(out, "chain.urdf"), "w") as f:
        f.write(urdf(n))
    with open(os.path.join(out, "chain_scene.yaml"), "w") as f:
        f.write(scene(n))


if __name__ == "__main__":
    main()
