# SPDX-License-Identifier: BSD-3-Clause
"""python3 -m pcl_probcollision.dask a b poses.txt --scheduler ADDRESS|local[:N] [pcd_collision flags]

Writes the JSON lines of `pcd_collision a b -poses poses.txt -json`, the poses answered on Dask."""
import sys

if __name__ == "__main__":  # LocalCluster's worker processes import this module again
    from pcl_probcollision.dask.cli import main

    sys.exit(main(sys.argv[1:]))
