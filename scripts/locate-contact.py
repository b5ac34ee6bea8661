#!/usr/bin/env python3
"""Where two meshes touch at a pose, which part of the fixed one it is, and which samples lie near.

A developer's tool for tracing a wrong answer of the evaluation (docs/SURFACE.md, "Where the
hidden collisions are"): given the meshes an evaluation workload was sampled from (W1: FCL's
piano and room, ../shared/data/meshes/piano_room_rob.obj and piano_room_env.obj) and a pose of
the moving one, it reports

- the contact: the moving mesh's surface samples within --band of the fixed mesh (their number,
  centre and extent), or the nearest distance when none is;
- the parts of the fixed mesh they touch (its connected components as stored): each part's
  axis-aligned box and its thickness (the smallest extent of its principal-axes box);
- with --env-cloud / --robot-cloud (the noisy clouds `evaluate_collision --dump` writes), the
  cloud samples nearest the contact's centre, with their normals when the file has them: what
  the method saw there.

The pose is pcd_collision's: p' = R p + t, R = Rz(yaw) Ry(pitch) Rx(roll), applied to the moving
mesh and cloud; --poses FILE --query N reads it from a dumped poses file (lines
"tx ty tz roll pitch yaw  # N ..."). The surface samples are drawn by area from a fixed seed, so
the same inputs print the same numbers. Needs numpy and Open3D (Debian's python3-open3d).

    python3 scripts/locate-contact.py --robot-mesh ../shared/data/meshes/piano_room_rob.obj \\
        --env-mesh ../shared/data/meshes/piano_room_env.obj \\
        --poses out/scans/W1_0.25_poses.txt --query 115 --env-cloud out/scans/W1_0.25_env.pcd

Exit status 0 on success (touching or not), 2 on a usage error (an option missing, or a value
out of range or malformed: the message names the option), 1 on a bad input file (the message
names it).
"""
import argparse
import json
import math
import pathlib
import sys


def fail(message):
    print(f"locate-contact: error: {message}", file=sys.stderr)
    sys.exit(1)


def parse_pose(text, where, refuse=fail):
    """Six finite numbers; refuse(message) otherwise (fail for a file's line, the parser's error
    for --pose)."""
    parts = text.replace(",", " ").split()
    if len(parts) != 6:
        refuse(f"{where}: expected 6 numbers tx,ty,tz,roll,pitch,yaw, got {len(parts)}")
    try:
        values = [float(v) for v in parts]
    except ValueError:
        refuse(f"{where}: '{text.strip()}' is not six numbers")
    if not all(math.isfinite(v) for v in values):
        refuse(f"{where}: every number must be finite")
    return values


def pose_from_file(path, query):
    try:
        lines = pathlib.Path(path).read_text().splitlines()
    except OSError as e:
        fail(f"cannot read '{path}': {e.strerror}")
    for number, line in enumerate(lines, 1):
        body, _, comment = line.partition("#")
        tag = comment.split()
        if body.strip() and tag and tag[0] == str(query):
            return parse_pose(body, f"{path}:{number}")
    fail(f"{path}: no pose of query {query} (lines 'tx ty tz roll pitch yaw  # {query} ...')")


def rotation(roll, pitch, yaw):
    import numpy as np
    cx, sx, cy, sy, cz, sz = (math.cos(roll), math.sin(roll), math.cos(pitch), math.sin(pitch),
                              math.cos(yaw), math.sin(yaw))
    rx = np.array([[1, 0, 0], [0, cx, -sx], [0, sx, cx]])
    ry = np.array([[cy, 0, sy], [0, 1, 0], [-sy, 0, cy]])
    rz = np.array([[cz, -sz, 0], [sz, cz, 0], [0, 0, 1]])
    return rz @ ry @ rx


def read_mesh(o3d, path, option):
    if not pathlib.Path(path).is_file():
        fail(f"{option}: cannot read '{path}': no such file")
    mesh = o3d.io.read_triangle_mesh(str(path))
    if len(mesh.triangles) == 0:
        fail(f"{option}: '{path}' holds no triangle")
    return mesh


def read_cloud(o3d, np, path, option):
    if not pathlib.Path(path).is_file():
        fail(f"{option}: cannot read '{path}': no such file")
    cloud = o3d.io.read_point_cloud(str(path))
    points = np.asarray(cloud.points)
    if len(points) == 0:
        fail(f"{option}: '{path}' holds no point")
    normals = np.asarray(cloud.normals) if cloud.has_normals() else None
    keep = np.isfinite(points).all(axis=1)
    return points[keep], (normals[keep] if normals is not None else None)


def surface_samples(np, mesh, count, seed):
    """count points uniformly by area over the mesh (seeded: the same points every run)."""
    v = np.asarray(mesh.vertices)
    t = np.asarray(mesh.triangles)
    a, b, c = v[t[:, 0]], v[t[:, 1]], v[t[:, 2]]
    area = 0.5 * np.linalg.norm(np.cross(b - a, c - a), axis=1)
    rng = np.random.default_rng(seed)
    pick = rng.choice(len(t), size=count, p=area / area.sum())
    r1, r2 = rng.random(count), rng.random(count)
    s = np.sqrt(r1)
    return (1 - s)[:, None] * a[pick] + (s * (1 - r2))[:, None] * b[pick] + (s * r2)[:, None] * c[pick]


def nearest_samples(np, points, normals, centre, count):
    d = np.linalg.norm(points - centre, axis=1)
    order = np.argsort(d, kind="stable")[:count]
    rows = []
    for i in order:
        row = {"index": int(i), "distance": float(d[i]), "point": points[i].tolist()}
        if normals is not None:
            row["normal"] = normals[i].tolist()
        rows.append(row)
    return rows


def check_usage(args, refuse):
    """The option values, before any file is read: refuse(message) (the parser's error, exit 2,
    as argparse's own for a value that is not a number) for one out of range. Returns the --pose
    given, or None."""
    if args.band <= 0 or not math.isfinite(args.band):
        refuse(f"--band: {args.band} must be finite and > 0")
    if args.samples < 1:
        refuse(f"--samples: {args.samples} must be >= 1")
    if args.nearest < 1:  # -3 was taken (a probe, 2026-12-03)
        refuse(f"--nearest: {args.nearest} must be >= 1")
    if args.seed < 0:
        refuse(f"--seed: {args.seed} must be >= 0")
    if (args.pose is None) == (args.poses is None):
        refuse("give the pose as --pose tx,ty,tz,roll,pitch,yaw or as --poses FILE --query N")
    if args.poses is not None and args.query is None:
        refuse("--poses needs --query N")
    return parse_pose(args.pose, "--pose", refuse) if args.pose is not None else None


def locate(args, pose=None):
    try:
        import numpy as np
        import open3d as o3d
    except ImportError as e:
        fail(f"needs numpy and Open3D (Debian: python3-numpy, python3-open3d): {e}")
    pose = pose if pose is not None else pose_from_file(args.poses, args.query)
    R = rotation(*pose[3:])
    t = np.array(pose[:3])

    robot = read_mesh(o3d, args.robot_mesh, "--robot-mesh")
    env = read_mesh(o3d, args.env_mesh, "--env-mesh")
    moved = surface_samples(np, robot, args.samples, args.seed) @ R.T + t
    scene = o3d.t.geometry.RaycastingScene()
    scene.add_triangles(o3d.t.geometry.TriangleMesh.from_legacy(env))
    query = o3d.core.Tensor(moved.astype(np.float32))
    closest = scene.compute_closest_points(query)
    distance = np.linalg.norm(closest["points"].numpy() - moved.astype(np.float32), axis=1).astype(float)
    near = distance < args.band
    report = {"pose": pose, "band": args.band, "samples": args.samples}
    if not near.any():
        i = int(np.argmin(distance))
        report["contact"] = None
        report["nearest_distance"] = float(distance[i])
        report["nearest_point"] = moved[i].tolist()
        centre = moved[i]
        touched = [int(closest["primitive_ids"].numpy()[i])]
    else:
        contact = moved[near]
        centre = contact.mean(axis=0)
        report["contact"] = {"samples": int(near.sum()), "centre": centre.tolist(),
                             "min": contact.min(axis=0).tolist(), "max": contact.max(axis=0).tolist()}
        touched = closest["primitive_ids"].numpy()[near].astype(int).tolist()

    cluster, _, _ = env.cluster_connected_triangles()
    cluster = np.asarray(cluster)
    triangles = np.asarray(env.triangles)
    vertices = np.asarray(env.vertices)
    parts = []
    for part in sorted(set(int(cluster[i]) for i in touched)):
        corners = vertices[np.unique(triangles[cluster == part])]
        centred = corners - corners.mean(axis=0)
        axes = np.linalg.svd(centred, full_matrices=False)[2] if len(corners) > 1 else np.eye(3)
        extent = np.ptp(centred @ axes.T, axis=0) if len(corners) > 1 else np.zeros(3)
        parts.append({"part": part, "contact_samples": int(sum(1 for i in touched if cluster[i] == part)),
                      "min": corners.min(axis=0).tolist(), "max": corners.max(axis=0).tolist(),
                      "thickness": float(np.sort(extent)[0])})
    report["env_parts"] = parts
    if args.env_cloud:
        points, normals = read_cloud(o3d, np, args.env_cloud, "--env-cloud")
        report["env_cloud_nearest"] = nearest_samples(np, points, normals, centre, args.nearest)
    if args.robot_cloud:
        points, normals = read_cloud(o3d, np, args.robot_cloud, "--robot-cloud")
        points = points @ R.T + t
        normals = normals @ R.T if normals is not None else None
        report["robot_cloud_nearest"] = nearest_samples(np, points, normals, centre, args.nearest)
    return report


def fmt(v, digits=1):
    return "(" + ", ".join(f"{x:.{digits}f}" for x in v) + ")"


def print_text(report):
    if report["contact"] is None:
        print(f"no contact within {report['band']:g}: nearest distance {report['nearest_distance']:.2f} "
              f"at {fmt(report['nearest_point'])}")
    else:
        c = report["contact"]
        print(f"contact: {c['samples']} of {report['samples']} surface samples within {report['band']:g}, "
              f"centre {fmt(c['centre'])}, extent {fmt(c['min'])} to {fmt(c['max'])}")
    for p in report["env_parts"]:
        print(f"env part {p['part']}: box {fmt(p['min'])} to {fmt(p['max'])}, thickness {p['thickness']:.1f}"
              f" ({p['contact_samples']} contact samples)")
    for key, name in (("env_cloud_nearest", "env cloud"), ("robot_cloud_nearest", "robot cloud")):
        for row in report.get(key, []):
            normal = f" normal {fmt(row['normal'], 2)}" if "normal" in row else ""
            print(f"{name} sample {row['index']}: {row['distance']:.1f} from the centre, at {fmt(row['point'])}"
                  f"{normal}")


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--robot-mesh", required=True, help="the moving object's mesh (input A)")
    parser.add_argument("--env-mesh", required=True, help="the fixed object's mesh (input B)")
    parser.add_argument("--pose", help="tx,ty,tz,roll,pitch,yaw of the moving object (pcd_collision's)")
    parser.add_argument("--poses", help="a poses file as evaluate_collision --dump writes it")
    parser.add_argument("--query", type=int, help="the query whose pose --poses holds")
    parser.add_argument("--env-cloud", help="the fixed object's cloud (PCD/PLY): its samples nearest the contact")
    parser.add_argument("--robot-cloud", help="the moving object's cloud, unposed")
    parser.add_argument("--band", type=float, default=2.0, help="contact within this distance (data units; 2)")
    parser.add_argument("--samples", type=int, default=400000, help="surface samples of the moving mesh (400000)")
    parser.add_argument("--nearest", type=int, default=8, help="cloud samples listed (8)")
    parser.add_argument("--seed", type=int, default=1, help="seed of the surface samples (1)")
    parser.add_argument("--json", action="store_true", help="one JSON object on stdout instead of text")
    args = parser.parse_args()
    report = locate(args, check_usage(args, parser.error))
    if args.json:
        print(json.dumps(report))
    else:
        print_text(report)


if __name__ == "__main__":
    main()
