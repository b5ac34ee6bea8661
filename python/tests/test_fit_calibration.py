"""scripts/fit-surface-calibration.py: the exponent it fits, and its refusals."""
import csv
import pathlib
import random
import subprocess
import sys

SCRIPT = pathlib.Path(__file__).resolve().parents[2] / "scripts" / "fit-surface-calibration.py"
FIELDS = ["workload", "noise_pct", "method", "setting", "near_sigma", "score", "exact_collision"]


def write_run(directory, gamma, count, seed, workloads=("F1", "F1-sparse")):
    """A run whose near-band poses collide with chance 0.1 + 0.8 u^gamma in the band (u the
    position of P in it), with P itself outside the band; both settings alike."""
    rng = random.Random(seed)
    directory.mkdir(parents=True)
    with open(directory / "queries.csv", "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=FIELDS)
        w.writeheader()
        for setting in ("surface", "pooled", "classifier"):
            for _ in range(count):
                p = rng.random()
                truth = 0.1 + 0.8 * ((p - 0.1) / 0.8) ** gamma if 0.1 <= p <= 0.9 else p
                w.writerow({"workload": rng.choice(list(workloads)), "noise_pct": "0.5", "method": "ours",
                            "setting": setting, "near_sigma": "1", "score": f"{p:.6f}",
                            "exact_collision": int(rng.random() < truth)})


def run(*args):
    return subprocess.run([sys.executable, str(SCRIPT), *map(str, args)], capture_output=True, text=True, timeout=120)


def test_recovers_the_exponent_of_an_over_stated_p(tmp_path):
    runs = [tmp_path / f"s{s}" for s in range(3)]
    for s, d in enumerate(runs):
        write_run(d, gamma=2.0, count=4000, seed=s)
    out = run(*runs)
    assert out.returncode == 0, out.stderr
    gammas = {line.split()[2]: float(line.split("=")[1].rstrip(";")) for line in out.stdout.splitlines()
              if line.startswith("constexpr")}
    assert set(gammas) == {"kSurfaceLayerGamma", "kPooledGamma"}
    for name, gamma in gammas.items():
        assert 1.7 <= gamma <= 2.3, (name, gamma)


def test_a_calibrated_p_needs_no_map(tmp_path):
    write_run(tmp_path / "s0", gamma=1.0, count=6000, seed=7)
    out = run(tmp_path / "s0")
    assert out.returncode == 0, out.stderr
    for line in out.stdout.splitlines():
        if line.startswith("constexpr"):
            assert float(line.split("=")[1].rstrip(";")) <= 1.2, line


def test_refuses_missing_runs_and_too_few_answers(tmp_path):
    out = run(tmp_path / "nowhere")
    assert out.returncode != 0 and "cannot read" in out.stderr and "nowhere" in out.stderr
    write_run(tmp_path / "small", gamma=1.0, count=20, seed=1)
    out = run(tmp_path / "small")
    assert out.returncode != 0 and "near-band" in out.stderr
    assert run().returncode != 0


def test_refuses_runs_of_a_reported_workload(tmp_path):
    write_run(tmp_path / "w1", gamma=2.0, count=4000, seed=3, workloads=("W1", "F1"))
    out = run(tmp_path / "w1")
    assert out.returncode != 0 and "W1" in out.stderr and "--fit-scene" in out.stderr


def test_refuses_a_malformed_queries_csv_by_file_and_line(tmp_path):
    # A queries.csv without the columns the fit reads ended in a KeyError traceback, a score that
    # is no number in a ValueError one: both now exit 1 naming the file (and the line).
    headless = tmp_path / "headless"
    headless.mkdir()
    (headless / "queries.csv").write_text("a,b\n1,2\n")
    out = run(headless)
    assert out.returncode == 1, out.stderr
    assert f"{headless}/queries.csv: not an evaluate_collision queries.csv (no column workload" in out.stderr
    write_run(tmp_path / "bad", gamma=1.0, count=200, seed=2)
    path = tmp_path / "bad" / "queries.csv"
    lines = path.read_text().splitlines()
    row = next(i for i, line in enumerate(lines) if ",ours,surface," in line)
    lines[row] = lines[row].rsplit(",", 2)[0] + ",abc," + lines[row].rsplit(",", 1)[1]
    path.write_text("\n".join(lines) + "\n")
    out = run(tmp_path / "bad")
    assert out.returncode == 1, out.stderr
    assert f"{path}:{row + 1}: score 'abc'" in out.stderr, out.stderr
    (tmp_path / "empty").mkdir()
    (tmp_path / "empty" / "queries.csv").write_text("")
    out = run(tmp_path / "empty")
    assert out.returncode == 1 and "not an evaluate_collision queries.csv" in out.stderr, out.stderr
    for out in (run(headless), run(tmp_path / "bad")):
        assert "Traceback" not in out.stderr
