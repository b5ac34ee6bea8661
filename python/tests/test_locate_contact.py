"""scripts/locate-contact.py: the contact, the part touched and its thickness, and its refusals."""
import json
import pathlib
import subprocess
import sys

import pytest

SCRIPT = pathlib.Path(__file__).resolve().parents[2] / "scripts" / "locate-contact.py"


def write_box(f, lo, hi, first):
    """A closed box as 8 shared vertices and 12 triangles (one connected part)."""
    (x0, y0, z0), (x1, y1, z1) = lo, hi
    for x, y, z in [(x0, y0, z0), (x1, y0, z0), (x1, y1, z0), (x0, y1, z0),
                    (x0, y0, z1), (x1, y0, z1), (x1, y1, z1), (x0, y1, z1)]:
        f.write(f"v {x} {y} {z}\n")
    for a, b, c in [(1, 3, 2), (1, 4, 3), (5, 6, 7), (5, 7, 8), (1, 2, 6), (1, 6, 5),
                    (2, 3, 7), (2, 7, 6), (3, 4, 8), (3, 8, 7), (4, 1, 5), (4, 5, 8)]:
        f.write(f"f {a + first} {b + first} {c + first}\n")


@pytest.fixture
def scene(tmp_path):
    # The fixed mesh: a panel 400 x 10 x 200 (top edge at z = 200) and, apart, a floor slab.
    env = tmp_path / "env.obj"
    with open(env, "w") as f:
        write_box(f, (0, 0, 0), (400, 10, 200), 0)
        write_box(f, (-100, -100, -20), (500, 100, -10), 8)
    robot = tmp_path / "robot.obj"
    with open(robot, "w") as f:
        write_box(f, (-50, -10, -10), (50, 10, 10), 0)  # a bar, long along x
    cloud = tmp_path / "env.pcd"
    cloud.write_text("VERSION 0.7\nFIELDS x y z normal_x normal_y normal_z\nSIZE 4 4 4 4 4 4\n"
                     "TYPE F F F F F F\nCOUNT 1 1 1 1 1 1\nWIDTH 3\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\n"
                     "POINTS 3\nDATA ascii\n300 5 200 0 0 1\n100 5 199 0 0 1\n100 5 -10 0 0 -1\n")
    return env, robot, cloud


def run(*args):
    return subprocess.run([sys.executable, str(SCRIPT), *map(str, args)], capture_output=True, text=True,
                          timeout=300)


def test_a_bar_pressed_into_a_panels_top_edge(scene):
    env, robot, cloud = scene
    # Turned a quarter about z (yaw), so the bar lies across the panel; its underside 5 below the edge.
    out = run("--robot-mesh", robot, "--env-mesh", env, "--pose", "100,5,205,0,0,1.5707963267948966",
              "--env-cloud", cloud, "--nearest", 2, "--samples", 20000, "--json")
    assert out.returncode == 0, out.stderr
    report = json.loads(out.stdout)
    contact = report["contact"]
    assert contact is not None and contact["samples"] > 0
    # Only the panel is touched: 10 thick, its box as written.
    assert len(report["env_parts"]) == 1
    part = report["env_parts"][0]
    assert part["thickness"] == pytest.approx(10.0, abs=1e-6)
    assert part["min"] == pytest.approx([0, 0, 0]) and part["max"] == pytest.approx([400, 10, 200])
    # Turned, the bar spans 20 along x (not 100) and reaches 5 below the edge.
    assert contact["max"][0] - contact["min"][0] <= 20.0 + 1e-6
    assert 90.0 - 1e-6 <= contact["centre"][0] <= 110.0 + 1e-6
    assert contact["min"][2] >= 195.0 - 1e-3 and contact["max"][2] <= 200.0 + 2.0
    nearest = report["env_cloud_nearest"]
    assert [row["index"] for row in nearest] == [1, 0]
    assert nearest[0]["normal"] == pytest.approx([0, 0, 1])


def test_a_gap_reports_the_nearest_distance(scene):
    env, robot, _ = scene
    out = run("--robot-mesh", robot, "--env-mesh", env, "--pose", "100,5,225,0,0,0", "--samples", 20000)
    assert out.returncode == 0, out.stderr
    assert out.stdout.startswith("no contact within 2: nearest distance")
    distance = float(out.stdout.split("nearest distance ")[1].split()[0])
    assert distance == pytest.approx(15.0, abs=0.5)


def test_a_pose_from_a_dumped_poses_file(scene, tmp_path):
    env, robot, _ = scene
    poses = tmp_path / "poses.txt"
    poses.write_text("# tx ty tz roll pitch yaw  # query, pose set, exact signed distance\n"
                     "100 5 225 0 0 0  # 0 uniform 15\n100 5 205 0 0 0  # 1 near_sigma -5\n")
    out = run("--robot-mesh", robot, "--env-mesh", env, "--poses", poses, "--query", 1, "--samples", 20000, "--json")
    assert out.returncode == 0, out.stderr
    report = json.loads(out.stdout)
    assert report["pose"] == [100, 5, 205, 0, 0, 0] and report["contact"] is not None


@pytest.mark.parametrize("args, named, status", [
    (["--env-mesh", "missing.obj"], "--env-mesh", 1),  # a bad file: 1
    (["--pose", "1,2,3"], "--pose", 2),  # a bad option value: a usage error, 2 (it exited 1)
    (["--band", "0"], "--band", 2),
    (["--band", "abc"], "--band", 2),  # argparse's own: 2 before too
    (["--nearest", "-3"], "--nearest: -3 must be >= 1", 2),
    (["--poses", "p.txt"], "--poses needs --query", 2),
])
def test_bad_input_is_refused_by_name(scene, args, named, status):
    env, robot, _ = scene
    base = {"--robot-mesh": robot, "--env-mesh": env, "--pose": "0,0,0,0,0,0"}
    for key, value in zip(args[::2], args[1::2]):
        base[key] = value
    if "--poses" in base:
        del base["--pose"]
    out = run(*[x for kv in base.items() for x in kv])
    assert out.returncode == status, out.stderr
    assert named in out.stderr
    assert "Traceback" not in out.stderr
