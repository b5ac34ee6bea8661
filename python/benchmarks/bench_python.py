#!/usr/bin/python3
# SPDX-License-Identifier: BSD-3-Clause
"""Python and Dask figures of issue #18 on a W1-like workload, with the C++ reference on the same cores.

    cmake --build build --target pcl_probcollision_bench_batch
    PYTHONPATH=build/python /usr/bin/python3 python/benchmarks/bench_python.py --build build

Workload (as benchmarks/bench_collide.cpp and W1): FCL's piano and room meshes
(../shared/data/meshes) sampled to about 10,000 points each, Gaussian noise of 0.5 % of the
piano's bounding-box diagonal on every sample, declared as isotropic noise; default parameters;
uniformly random piano poses in the room's bounding box. Prints figures, asserts nothing.

Exit status 0 after the figures, 2 on a usage error (a bad option or value), 1 when something it
needs is missing (the module, the bench binary, the meshes)."""
import argparse
import json
import math
import os
import pathlib
import subprocess
import sys
import tempfile
import time

import numpy as np

ROOT = pathlib.Path(__file__).resolve().parents[2]
pc = pcd = None  # pcl_probcollision and its dask layer, imported by main() once the options are read


def import_module(build):
    """pcl_probcollision from PYTHONPATH, else from BUILD/python; exit 1 naming both when neither
    has it (it ended in an import traceback, even for --help)."""
    global pc, pcd
    try:
        import pcl_probcollision
    except ImportError:
        sys.path.insert(0, str(pathlib.Path(build) / "python"))
        try:
            import pcl_probcollision
        except ImportError as e:
            sys.exit(f"bench_python.py: cannot import pcl_probcollision from PYTHONPATH or {build}/python ({e}); "
                     f"build it (cmake --build {build}) or set PYTHONPATH=BUILD/python")
    from pcl_probcollision import dask as dask_layer
    pc, pcd = pcl_probcollision, dask_layer


def at_least(low):
    """An argparse type: an integer >= low (argparse's error, exit 2, otherwise)."""
    def read(text):
        try:
            value = int(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"'{text}' is not an integer") from None
        if value < low:
            raise argparse.ArgumentTypeError(f"{value} must be at least {low}")
        return value
    return read


def mesh_area(V, F):
    return 0.5 * np.linalg.norm(np.cross(V[F[:, 1]] - V[F[:, 0]], V[F[:, 2]] - V[F[:, 0]]), axis=1).sum()


def noisy_samples(path, target, sigma, seed):
    V, F = pc.read_mesh(path)
    area_points = max(0.5 * target, target - len(V))
    pts = pc.sample_mesh(V, F, math.sqrt(mesh_area(V, F) / area_points), seed).astype(np.float64)
    pts += np.random.default_rng(seed + 1).normal(scale=sigma, size=pts.shape)
    return pts.astype(np.float32)


def random_poses(lo, hi, m, seed):
    """T_room_piano: translation uniform in the room's box, rotation uniform."""
    rng = np.random.default_rng(seed)
    q = rng.normal(size=(m, 4))
    q /= np.linalg.norm(q, axis=1, keepdims=True)
    w, x, y, z = q.T
    R = np.stack([np.stack([1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)], -1),
                  np.stack([2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)], -1),
                  np.stack([2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)], -1)], 1)
    T = np.tile(np.eye(4), (m, 1, 1))
    T[:, :3, :3] = R
    T[:, :3, 3] = lo + (hi - lo) * rng.uniform(size=(m, 3))
    return T


def best(f, repeats=3):
    times = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        f()
        times.append(time.perf_counter() - t0)
    return min(times)


def cpp(exe, d, threads, repeats=3):
    out = subprocess.run([exe, d, str(threads), str(repeats)], capture_output=True, text=True, check=True)
    return json.loads(out.stdout)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--build", default=str(ROOT / "build"))
    ap.add_argument("--shared", default=os.environ.get("PCL_PROBCOLLISION_SHARED_DATA", str(ROOT.parent / "shared" / "data")))
    ap.add_argument("--poses", type=at_least(1), default=2000)
    ap.add_argument("--dask-poses", type=at_least(1), default=20000)
    ap.add_argument("--chunk-size", type=at_least(1), default=None)
    args = ap.parse_args()
    exe = pathlib.Path(args.build) / "python" / "pcl_probcollision_bench_batch"
    if not os.access(exe, os.X_OK):
        sys.exit(f"bench_python.py: {exe}: no such executable (cmake --build {args.build} --target "
                 f"pcl_probcollision_bench_batch)")
    meshes = pathlib.Path(args.shared) / "meshes"
    for name in ("piano_room_rob.obj", "piano_room_env.obj"):
        if not (meshes / name).is_file():
            sys.exit(f"bench_python.py: {meshes / name}: no such file (--shared names the shared data directory)")
    import_module(args.build)

    V, F = pc.read_mesh(meshes / "piano_room_rob.obj")
    sigma = 0.005 * pc.mesh_diagonal(V, F)
    piano = noisy_samples(meshes / "piano_room_rob.obj", 10000, sigma, 1)
    room = noisy_samples(meshes / "piano_room_env.obj", 10000, sigma, 2)
    lo, hi = room.min(axis=0).astype(np.float64), room.max(axis=0).astype(np.float64)
    T_room_piano = random_poses(lo, hi, max(args.poses, args.dask_poses), 3)
    T_a_b = pc.invert_poses(T_room_piano)  # collide(piano, room, T_piano_room)
    params = pc.CloudModelParams(noise=pc.SensorNoiseModel.isotropic(sigma))
    print(f"workload: piano {len(piano)} points, room {len(room)} points, isotropic sigma {sigma:.3f} (0.5 % of the "
          f"piano's diagonal), default parameters, random poses in the room; {os.cpu_count()} cores")

    with tempfile.TemporaryDirectory() as d:
        piano.tofile(f"{d}/a.f32")
        room.tofile(f"{d}/b.f32")
        pathlib.Path(f"{d}/sigma.txt").write_text(repr(sigma))
        np.ascontiguousarray(T_a_b[:args.poses]).tofile(f"{d}/poses.f64")
        A = pc.build_model(piano, params=params)
        B = pc.build_model(room, params=params)
        request = pc.CollisionRequest()
        print(f"\n1. collide_batch on {args.poses} poses (best of 3) vs C++ collideBatch on the same models' points")
        for threads in (1, 2):
            c = cpp(str(exe), d, threads)
            t = best(lambda: pc.collide_batch(A, B, T_a_b[:args.poses], request, threads=threads))
            rs = pc.collide_batch(A, B, T_a_b[:args.poses], request, threads=threads)
            same = math.isclose(sum(r.probability for r in rs), c["sum_p"], rel_tol=0, abs_tol=0)
            print(f"   threads {threads}: C++ {c['poses_per_s']:.0f} poses/s, Python {args.poses / t:.0f} poses/s "
                  f"({100 * (c['batch_s'] / t - 1):+.1f} % throughput), same sum of P: {same}")

        print("\n2. per-call overhead of collide (20,000 calls on a pose far outside the room: no leaf pair)")
        far = np.eye(4)
        far[:3, 3] = 100 * (hi - lo) + hi
        n = 20000
        t_call = best(lambda: [pc.collide(A, B, far) for _ in range(n)]) / n
        farbatch = np.tile(far, (n, 1, 1))
        t_batch = best(lambda: pc.collide_batch(A, B, farbatch, threads=1)) / n
        print(f"   collide() {t_call * 1e6:.2f} us per call, the same query inside collide_batch {t_batch * 1e6:.2f} us: "
              f"overhead {(t_call - t_batch) * 1e6:.2f} us per call")

        print("\n3. building the piano's model (median of 5): numpy float32 vs a PCL cloud")
        c = cpp(str(exe), d, 1, 1)
        ts = sorted(best(lambda: pc.build_model(piano, params=params), 1) for _ in range(5))
        print(f"   C++ from pcl::PointCloud {c['build_a_ms']:.1f} ms, Python from numpy {ts[2] * 1e3:.1f} ms "
              f"({100 * (ts[2] * 1e3 / c['build_a_ms'] - 1):+.1f} %)")

        m = args.dask_poses
        P = T_room_piano[:m]
        np.ascontiguousarray(T_a_b[:m]).tofile(f"{d}/poses.f64")
        print(f"\n4. Dask LocalCluster, single-threaded worker processes, on {m} poses (after a warm-up call that "
              f"scatters the clouds and builds the models)")
        c1, c2 = cpp(str(exe), d, 1, 1), cpp(str(exe), d, 2, 1)
        print(f"   C++ collideBatch: 1 thread {c1['poses_per_s']:.0f} poses/s, 2 threads {c2['poses_per_s']:.0f} poses/s")
        from distributed import Client, LocalCluster
        ref = None
        rates = {}
        for workers in (1, 2):
            with LocalCluster(n_workers=workers, threads_per_worker=1, processes=True, dashboard_address=None) as lc, \
                    Client(lc) as client:
                opts = dict(client=client, sigma=sigma, chunk_size=args.chunk_size)
                pcd.collide_poses(piano, room, P[:200], **opts)
                t0 = time.perf_counter()
                r = pcd.collide_poses(piano, room, P, **opts)
                wall = time.perf_counter() - t0
                rates[workers] = m / wall
                ref = r if ref is None else ref
                same = np.array_equal(r.probability, ref.probability) and np.array_equal(r.verdict, ref.verdict)
                print(f"   {workers} worker(s): {m / wall:.0f} poses/s ({wall:.2f} s), chunk size {r.chunk_size} "
                      f"({r.chunks} chunks), answers identical to 1 worker: {same}")
                if workers == 2:
                    far_poses = np.tile(np.linalg.inv(far), (m, 1, 1))
                    walls = {}
                    for chunk in (20, 2000):
                        t0 = time.perf_counter()
                        pcd.collide_poses(piano, room, far_poses, client=client, sigma=sigma, chunk_size=chunk)
                        walls[chunk] = time.perf_counter() - t0
                    per_chunk = (walls[20] - walls[2000]) / (m / 20 - m / 2000) * workers
                    print(f"   per-chunk overhead (trivial poses, chunks of 20 vs 2000 on 2 workers): "
                          f"{per_chunk * 1e3:.2f} ms per chunk per worker")
        print(f"   speed-up 2 workers / 1 worker: {rates[2] / rates[1]:.2f}x; 2 workers vs C++ 2 threads: "
              f"{100 * (rates[2] / c2['poses_per_s'] - 1):+.1f} %")


if __name__ == "__main__":
    sys.exit(main())
