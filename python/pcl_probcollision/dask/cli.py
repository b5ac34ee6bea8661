# SPDX-License-Identifier: BSD-3-Clause
"""The command line of `python3 -m pcl_probcollision.dask`: pcd_collision's batch mode with the poses
answered on Dask. Same flags (-sigma, -sensor, ...; docs/CLI.md), same JSON lines on stdout as
`pcd_collision a b -poses FILE -json`, same warnings on stderr, same exit status (1 runtime failure,
2 usage error). pcd_collision's own parser judges its flags and the poses file here too, so both
refuse the same arguments in the same words."""
import os
import re
import sys
import time
import warnings

import numpy as np

from .. import _core as core
from . import _MESH_EXTENSIONS, _SWITCHES, _VALUES, InputWarning, check_input_kinds, collide_poses, connect, prepare_input, resolve_options

USAGE = """usage: python3 -m pcl_probcollision.dask <a> <b> <poses.txt> --scheduler ADDRESS|local[:N] [options]

Answers every pose of <poses.txt> (pcd_collision's -poses format; - reads standard input) on Dask
workers and prints the JSON lines of `pcd_collision <a> <b> -poses <poses.txt> -json`.

  --scheduler ADDRESS|local[:N]  a running scheduler (tcp://host:8786) or a LocalCluster of N
                                 single-threaded worker processes (default N = cores)
  --timeout S                    seconds to reach the scheduler (default 10)
  --chunk-size N                 poses per task (default: about 8 tasks per worker thread)
  -threads N                     threads of each task's batch (default 1: the workers give the
                                 parallelism; 0: one per core of the worker's machine)
  pcd_collision's options: -sensor -sensor_a -sensor_b -sigma -sigma_a -sigma_b -k -thresholds
  -measured -deterministic -stochastic -seed -exhaustive -defer_kernel_fits -max_leaf_fits -max_surface_pairs
  -noise_resolution -noise_resolution_gate -noise_stop -surface -surface_pooled -surface_ladder -surface_calibrated -distance -ignore_normals -closed -closed_a
  -closed_b -orientation -orientation_a -orientation_b -nmax -sigma_max
  -epsilon -split -mesh_density -json (accepted; the output is always JSON lines) -v. A value is
  the next argument or follows '='. -surface (experimental) adds the signed distance between the
  surfaces.
  -h, -help, --help              this help
  -version, --version            the versions of this command and of the library

On a terminal, stderr shows pcd_collision's progress line ([answered/total poses]) while the batch
runs; its warnings (units, rounding far from the origin, ...) are printed in its words.

Exit status, as pcd_collision's: 0 every pose answered, 1 a runtime failure (an unreadable input,
a malformed poses file, a failed query), 2 a usage error (a bad option or value, an unsupported
input type), found before the scheduler is reached.
"""

_SWITCH = (*_SWITCHES, "json", "v")  # -json and -v are taken and change nothing: the output is always JSON lines
_OWN = {"scheduler": str, "timeout": float, "chunk-size": int}
_FLOAT = re.compile(r"[+-]?([0-9]+\.?[0-9]*|\.[0-9]+)([eE][+-]?[0-9]+)?\Z")  # ASCII digits, as pcd_collision
_INT = re.compile(r"[+-]?[0-9]+\Z")


def _as_flag_message(message):
    """The library's and collide_poses' messages in this command line's words: no C++ scope
    ("[pcl_probcollision::BVHParams::validate] "), and an option named with its dash."""
    message = re.sub(r"^\[[^\]]*\] ", "", message)
    match = re.match(r"option (?!-)(\w+)", message)
    if match:
        return "option " + _flag(match.group(1)) + message[match.end():]
    match = re.match(r"(\w+) ", message)  # "epsilon 0.7 outside [0, 0.5)"
    if match and match.group(1) in _VALUES:
        return "option " + _flag(match.group(1)) + ": " + message[match.end():]
    return message


class Usage(Exception):
    pass


class Failure(Exception):
    pass


def _flag(name):
    """A flag as written on this command line: pcd_collision's with one dash, its own with two."""
    return ("--" if name in _OWN else "-") + name


def _own_value(flag, text, kind):
    """A value of this command's own options (pcd_collision's are judged by its parser)."""
    if kind is float and not _FLOAT.match(text):
        raise Usage(f"option {_flag(flag)}: '{text}' is not a number")
    if kind is int and not _INT.match(text):
        raise Usage(f"option {_flag(flag)}: '{text}' is not an integer")
    return kind(text)


def _typed(name, text):
    """A value pcd_collision's parser has accepted, as collide_poses takes it."""
    kind = _VALUES[name]
    if kind == "pair":
        return tuple(float(t) for t in text.split(","))
    return int(text) if kind in (int, "u64") else float(text) if kind is float else text


def parse(argv):
    """(positional, options for collide_poses, own options) or Usage. pcd_collision's flags and
    values are judged by pcd_collision's own parser (core.pcd_collision_usage_error: the same
    rules, the same words); this command adds its own options, which take two dashes, and its
    third argument, the poses file."""
    positional, options, own, seen = [], {}, {"scheduler": None, "timeout": 10.0, "chunk-size": None}, set()
    # -h and -version win over every other argument, as in pcd_collision (an unknown option beside them too).
    options_part = argv[:argv.index("--") if "--" in argv else len(argv)]
    if any(a in ("-h", "-help", "--help") for a in options_part):
        raise SystemExit(print(USAGE, end="") or 0)
    if any(a in ("-version", "--version") for a in options_part):
        raise SystemExit(print(f"pcl_probcollision.dask {core.__version__} (library {core.__version__})") or 0)
    flags, values = [], {}  # pcd_collision's flags as given; their values, by name
    i, only_positional = 0, False
    while i < len(argv):
        arg = argv[i]
        i += 1
        if only_positional or not arg.startswith("-") or arg == "-":
            positional.append(arg)
            continue
        if arg == "--":
            only_positional = True
            continue
        name, eq, value = arg.lstrip("-").partition("=")
        if name in ("pose", "poses"):
            raise Usage(f"option -{name} is not supported here: the poses file is the third argument")
        if name == "o":
            raise Usage("option -o is not supported here: the per-point results stay on the workers (use "
                        "pcd_collision -pose ... -o FILE for one pose)")
        dashes = len(arg) - len(arg.lstrip("-"))
        # pcd_collision's options take one dash, as there; this command's own take two.
        if dashes != (2 if name in _OWN else 1):
            raise Usage(f"unknown option '{arg.partition('=')[0]}'")
        if name in _OWN:
            if name in seen:
                raise Usage(f"option {_flag(name)} given twice")
            seen.add(name)
            if not eq:
                if i >= len(argv):
                    raise Usage(f"option {_flag(name)} needs a value")
                value = argv[i]
                i += 1
            own[name] = _own_value(name, value, _OWN[name])
            continue
        if name not in _VALUES and name not in _SWITCH:  # in pcd_collision's words
            raise Usage(core.pcd_collision_usage_error([arg]))
        flags.append(arg)
        if name in _VALUES and not eq and i < len(argv):
            value = argv[i]
            flags.append(value)
            i += 1
        values[name] = value if name in _VALUES else None
    if len(positional) != 3:
        raise Usage(f"expected <a> <b> <poses.txt>, got {len(positional)} argument(s)")
    error = core.pcd_collision_usage_error(positional[:2] + ["-poses", positional[2]] + flags)
    if error:
        raise Usage(error)
    for name, value in values.items():
        if name in _VALUES:
            options[name] = _typed(name, value)
        elif name not in ("json", "v"):
            options[name] = True
    if own["scheduler"] is None:
        raise Usage("--scheduler ADDRESS|local[:N] is required")
    scheduler = own["scheduler"]  # an address (tcp://host:8786, localhost:8786) is checked by connecting
    if scheduler.startswith("local:"):
        count = scheduler[len("local:"):]
        if not (_INT.match(count) and int(count) >= 1):
            raise Usage(f"option --scheduler: local:N needs a whole number N >= 1, got '{scheduler}'")
    if own["chunk-size"] is not None and own["chunk-size"] < 1:
        raise Usage(f"option --chunk-size: must be >= 1, got {own['chunk-size']}")
    if not own["timeout"] > 0:
        raise Usage(f"option --timeout: must be > 0, got {own['timeout']}")
    return positional, options, own


def _summary(spec, surface, merged):
    """What pcd_collision's JSON line says of an input (pcd_collision_json_lines' input_a/_b)."""
    d = {"path": spec["path"], "kind": spec["kind"], "points": len(spec["points"]), "load_ms": spec["load_ms"],
         "merged_samples": merged, "surface": surface}
    if spec["kind"] == "cloud":
        d.update(finite=spec["finite"], width=spec["width"], height=spec["height"])
    else:
        d.update(vertices=len(spec["vertices"]), triangles=len(spec["triangles"]), spacing=spec["spacing"],
                 spacing_source=spec["spacing_source"], sample_ms=spec.get("sample_ms", 0.0))
    return d


def json_lines(r, pose_rows, o, a, b):
    """pcd_collision's JSON lines for every pose, written by pcd_collision's own writer (docs/CLI.md)."""
    from . import _as_flags

    return core.pcd_collision_json_lines(_as_flags(o), _summary(a, r.surfaces["a"], r.merged_samples["a"]),
                                         _summary(b, r.surfaces["b"], r.merged_samples["b"]), r.fields, pose_rows,
                                         r.build_ms)


class Progress:
    """pcd_collision's progress line: "\\r[k/n poses]" on stderr when it is a terminal, drawn at
    most every 0.2 s (a short batch shows nothing) and erased before anything else is printed."""

    DELAY = 0.2

    def __init__(self, stream):
        self.stream = stream
        self.enabled = stream.isatty()
        self.last = time.monotonic()
        self.shown = False

    def __call__(self, done: int, total: int) -> None:
        now = time.monotonic()
        if not self.enabled or done >= total or now - self.last < self.DELAY:
            return
        self.last = now
        self.stream.write(f"\r[{done}/{total} poses]")
        self.stream.flush()
        self.shown = True

    def clear(self) -> None:
        if self.shown:
            self.stream.write("\r\033[K")
            self.stream.flush()
            self.shown = False


def main(argv):
    prog = "pcl_probcollision.dask"
    client = None
    try:
        positional, options, own = parse(argv)
        path_a, path_b, poses_path = positional
        try:  # option values pcd_collision refuses are usage errors (exit 2), found before any work
            resolve_options(options)
        except (TypeError, ValueError) as e:
            raise Usage(_as_flag_message(str(e))) from None
        try:
            # A malformed file fails before the (slow) loading; "-" is standard input, as for pcd_collision.
            pose_rows = core.parse_poses(sys.stdin.buffer.read()) if poses_path == "-" else core.read_poses(poses_path)
            # -surface without -ignore_normals: a cloud file's stored normals, as pcd_collision reads them.
            stored = bool(options.get("surface") or options.get("surface_pooled") or options.get("surface_ladder")) and not options.get("ignore_normals")
            # Named as pcd_collision names its models (a model's messages say which).
            a = prepare_input(path_a, "input", stored)
            b = prepare_input(path_b, "target", stored)
            try:  # a noise model given to a mesh, a mesh's spacing to two clouds: usage errors, before the scheduler
                check_input_kinds(a, b, options)
            except ValueError as e:
                raise Usage(_as_flag_message(str(e))) from None
        except IsADirectoryError as e:
            raise Failure(f"cannot read '{e.filename}': is a directory") from None
        except FileNotFoundError as e:
            raise Failure(f"cannot read '{e.filename}': No such file or directory") from None
        except ValueError as e:
            raise Failure(str(e).removeprefix("path: ").removeprefix("text: ")) from None
        t0 = time.perf_counter()
        client = connect(own["scheduler"], timeout=own["timeout"])
        print(f"Scheduler {own['scheduler']} [done, {(time.perf_counter() - t0) * 1e3:.1f} ms : "
              f"{len(client.nthreads())} workers, {sum(client.nthreads().values())} threads]", file=sys.stderr)
        try:
            # pcd_collision's warnings (units, rounding, a model's precision, meshes' samples) come
            # as InputWarnings: printed on stderr as pcd_collision prints them, once each.
            progress = Progress(sys.stderr)
            with warnings.catch_warnings(record=True) as said:
                warnings.simplefilter("always", InputWarning)
                try:
                    r = collide_poses(a, b, pose_rows, client=client, chunk_size=own["chunk-size"], progress=progress,
                                      **options)
                finally:
                    progress.clear()
            for w in said:
                if issubclass(w.category, InputWarning):
                    print(f"{prog}: warning: {w.message}", file=sys.stderr)
                else:
                    warnings.showwarning(w.message, w.category, w.filename, w.lineno)
        except (TypeError, ValueError) as e:
            # the options passed above: what fails here is the data (a cloud without a spacing, a
            # pose out of range), a runtime failure as in pcd_collision (exit 1)
            raise Failure(str(e)) from None
        bad = np.flatnonzero(r.status != 0)
        if bad.size:
            raise Failure(f"pose {bad[0]}: query failed")
        out = sys.stdout
        for line in json_lines(r, pose_rows, options, r.inputs[0], r.inputs[1]):
            out.write(line + "\n")
        out.flush()
        return 0
    except Usage as e:
        print(f"{prog}: error: {e}", file=sys.stderr)
        return 2
    except (Failure, ConnectionError, OSError, ValueError, RuntimeError) as e:
        print(f"{prog}: error: {e}", file=sys.stderr)
        return 1
    finally:
        if client is not None:
            cluster = getattr(client, "cluster", None)
            client.close()
            if cluster is not None:
                cluster.close()
