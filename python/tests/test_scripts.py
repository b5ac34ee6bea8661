# SPDX-License-Identifier: BSD-3-Clause
"""The scripts' command lines (a probe, 2026-12-03): --help prints the usage and exits 0, a bad
argument exits 2 naming it (no traceback), and a relative output path is the caller's."""
import os
import pathlib
import subprocess
import sys

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[2]
SCRIPTS = ROOT / "scripts"


def run(args, cwd=None):
    return subprocess.run(args, capture_output=True, text=True, cwd=cwd, timeout=120)


@pytest.mark.parametrize("script", ["fit-surface-calibration.py", "probe-face-contact.py", "locate-contact.py"])
def test_python_scripts_help(script):
    r = run([sys.executable, str(SCRIPTS / script), "--help"])
    assert r.returncode == 0, r.stderr
    assert "usage" in (r.stdout + r.stderr).lower() or "Fit the surface layer" in r.stdout


@pytest.mark.parametrize("args, words", [
    (["probe-face-contact.py", "--seed", "-1"], "argument --seed: -1 must be at least 0"),
    (["probe-face-contact.py", "--points", "abc"], "argument --points: 'abc' is not an integer"),
    (["fit-surface-calibration.py"], "usage: fit-surface-calibration.py RUN_DIR..."),
    (["fit-surface-calibration.py", "--bogus"], "usage: fit-surface-calibration.py RUN_DIR..."),
])
def test_python_scripts_refuse_bad_arguments(args, words):
    r = run([sys.executable, str(SCRIPTS / args[0])] + args[1:])
    assert r.returncode == 2, (r.returncode, r.stderr)
    assert words in r.stderr, r.stderr
    assert "Traceback" not in r.stderr


def test_locate_contact_refuses_a_count_below_one():
    # An option's bad value is a usage error: exit 2 naming it, as argparse's own refusal of a
    # value that is no number (--nearest -3 was taken; then it exited 1, --nearest abc 2).
    for flag, value in (("--nearest", "-3"), ("--seed", "-1"), ("--nearest", "abc")):
        r = run([sys.executable, str(SCRIPTS / "locate-contact.py"), "--robot-mesh", "a.obj", "--env-mesh", "b.obj",
                 "--pose", "0,0,0,0,0,0", flag, value])
        assert r.returncode == 2, r.stderr
        assert f"argument {flag}: invalid int value: '{value}'" in r.stderr if value == "abc" else \
            f"error: {flag}: {value} must be >= " in r.stderr, r.stderr
        assert "Traceback" not in r.stderr


@pytest.mark.parametrize("script", ["demo-picture.sh", "measure-large-cloud.sh"])
def test_shell_scripts_help_and_bad_arguments(script):
    helped = run(["bash", str(SCRIPTS / script), "--help"])
    assert helped.returncode == 0 and helped.stdout.startswith("usage:"), helped.stderr
    refused = run(["bash", str(SCRIPTS / script), "--bogus"])
    assert refused.returncode == 2 and refused.stderr.startswith("usage:"), refused.stderr


def test_demo_picture_writes_a_relative_out_where_it_is_called(tmp_path):
    tool = os.environ.get("PCL_PROBCOLLISION_PCD_COLLISION")
    assert tool, "PCL_PROBCOLLISION_PCD_COLLISION (set by ctest) names the built pcd_collision"
    r = run(["bash", str(SCRIPTS / "demo-picture.sh"), "--out=pose2.png", f"--tool={tool}"], cwd=tmp_path)
    assert r.returncode == 0, r.stderr
    assert (tmp_path / "pose2.png").stat().st_size > 1000
    assert not (ROOT / "pose2.png").exists()


def test_bench_python_help_and_refusals(tmp_path):
    # bench_python.py imported pcl_probcollision before reading its options, so --help without
    # PYTHONPATH ended in an import traceback; --poses 0 and a --shared without the meshes went on
    # to tracebacks of their own. Now --help exits 0, a bad value 2 and a missing mesh 1, by name.
    bench = ROOT / "python" / "benchmarks" / "bench_python.py"
    env = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}

    def bench_run(*args):
        return subprocess.run([sys.executable, str(bench), *map(str, args)], capture_output=True, text=True,
                              cwd=tmp_path, env=env, timeout=120)

    helped = bench_run("--help")
    assert helped.returncode == 0 and helped.stdout.startswith("usage: bench_python.py"), helped.stderr
    for args, words in ((["--poses", "0"], "argument --poses: 0 must be at least 1"),
                        (["--dask-poses", "-5"], "argument --dask-poses: -5 must be at least 1"),
                        (["--chunk-size", "abc"], "argument --chunk-size: 'abc' is not an integer")):
        refused = bench_run(*args)
        assert refused.returncode == 2 and words in refused.stderr, refused.stderr
    build = tmp_path / "build"
    (build / "python").mkdir(parents=True)
    exe = build / "python" / "pcl_probcollision_bench_batch"
    exe.write_text("#!/bin/sh\nexit 0\n")
    exe.chmod(0o755)
    missing = bench_run("--build", build, "--shared", tmp_path)
    assert missing.returncode == 1, missing.stderr
    assert f"{tmp_path / 'meshes' / 'piano_room_rob.obj'}: no such file" in missing.stderr
    assert "Traceback" not in missing.stderr
    for r in (helped, refused):
        assert "Traceback" not in r.stderr
