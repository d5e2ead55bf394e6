#!/usr/bin/env bash
# The Table 1 FEM campaign behind softbend.datasets.table1_fem(), in 8 shards.
#
#   bash campaigns/table1_fem/run.sh shard K [WORKERS]   # sweep shard K of 8 (resumes)
#   bash campaigns/table1_fem/run.sh next [WORKERS]      # the first shard not yet complete
#   bash campaigns/table1_fem/run.sh ship                # merge the shards, write the dataset
#
# Each shard is every 8th design of Table 1 (122 or 121 designs, about 20 CPU
# minutes per 60 designs); campaigns/shards.sh runs, resumes and ships them:
# 'ship' merges the shards (every one complete) into table1_fem.duckdb (not kept
# in git) and writes the package's dataset src/softbend/data/table1_fem
# (Parquet, provenance, checksums).
set -euo pipefail
cd "$(dirname "$0")/../.."
here=campaigns/table1_fem
shards=8
space=(--space table1 --backend fem)
merged=$here/table1_fem.duckdb
dataset=src/softbend/data/table1_fem
space_text=table1
description="Paper B Table 1 (972 designs) swept by softbend's 3D FEM with its default options, 0 to 0.5 MPa in 0.005 MPa outputs, each sweep ending at the last pressure, 300 degrees, the stretch limit of the material model or an inflation instability."
source campaigns/shards.sh
shards_main "$@"
