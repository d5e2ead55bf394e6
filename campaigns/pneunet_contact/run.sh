#!/usr/bin/env bash
# The PneuNet dataset with wall-to-wall contact (softbend.datasets' pneunet, again), in 16 shards.
#
#   bash campaigns/pneunet_contact/run.sh shard K [WORKERS]   # sweep shard K of 16 (resumes)
#   bash campaigns/pneunet_contact/run.sh next [WORKERS]      # the first shard not yet complete
#   bash campaigns/pneunet_contact/run.sh ship                # merge the shards, write the dataset
#
# The same seeded Sobol sample as the contact-free dataset (256 designs, seed 0),
# each swept with --contact on from 0 to 50 kPa or 180 degrees (about 35 CPU s
# for the reference design on one thread). Each shard is every 16th design;
# campaigns/shards.sh runs, resumes and ships them: 'ship' merges the shards
# (every one complete) into pneunet_contact.duckdb (not kept in git) and writes
# the package's dataset src/softbend/data/pneunet (Parquet, provenance, checksums).
set -euo pipefail
cd "$(dirname "$0")/../.."
here=campaigns/pneunet_contact
shards=16
space=(--family pneunet --space sobol:256 --seed 0 --contact on)
merged=$here/pneunet_contact.duckdb
dataset=src/softbend/data/pneunet
space_text=sobol:256
description="256 PneuNets (softbend's pneunet family: 3-8 chambers 5-12 mm long, 10-20 mm wide and 8-25 mm tall, expanding walls 0.8-2.5 mm, outer walls 1.5-3 mm, gaps 1-5 mm, base 1-4 mm; a scrambled Sobol sample, seed 0) swept by softbend's 3D FEM with the family's default options (Elastosil M4601, a 0.1 mm paper strain-limiting layer, no gravity, element size at most 3 mm and 2.5 times the thinnest wall, frictionless penalty contact between the facing walls of neighbouring chambers at 50 MPa/mm), 0 to 50 kPa in 1 kPa outputs, each sweep ending at the last pressure, at 180 degrees of bending, or where Newton stops converging."
source campaigns/shards.sh
shards_main "$@"
