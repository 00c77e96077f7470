#!/usr/bin/env bash
# A faulty site, for bench/scenarios/learn_damaged_round.sh (issue 62): submits a learner's round through the
# project's own deploy/slurm/submit-dataset.sh, but its workers run the micro-model with another
# scene and record the campaign's scene in their shards, as a worker with a stale scene file or
# another build's defaults would: a damage no provenance check can see, left to the learner's gate.
# The damage: FAULTY_SCENE_SET, scene assignments separated by spaces (default: Coulomb adhesion of
# 0.1 at the contact points, which the campaign's scene does not have, as another version's default
# interface law would add). Used as `mufric learn run --slurm-submit bench/scenarios/faulty_site/submit-dataset.sh`.
set -euo pipefail
here=$(dirname "$(realpath "$0")")
export FAULTY_REAL_MUFRIC=$(realpath "${MUFRIC:-$(command -v mufric)}")
export FAULTY_SCENE_SET=${FAULTY_SCENE_SET:-contact.law=coulomb contact.adhesive_coefficient=0.1}
export MUFRIC=$here/faulty-mufric
exec bash "$here/../../../deploy/slurm/submit-dataset.sh" "$@"
