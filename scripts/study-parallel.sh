#!/usr/bin/env bash
# Runs a study's jobs through GNU parallel (Debian package `parallel`, installed by
# scripts/setup.sh): on this machine's cores, or on several hosts with --sshlogin. The job
# index is the whole interface: every job is `wheelins study run STUDY --job K`, and parallel
# schedules them (docs/studies.md). With several hosts the study file, the wheelins binary
# and the results directory must be at the same paths on every host (a shared file system).
#
# Usage: scripts/study-parallel.sh [options] STUDY.yaml [-- PARALLEL_OPTIONS...]
#   -j N               jobs at once per host (default: one per core)
#   --sshlogin LIST    hosts in parallel's syntax, e.g. 8/node1,8/node2,: (":" is this machine)
#   --wheelins PATH    the wheelins binary (default: build/wheelins of this checkout, else PATH)
#   --results DIR      results directory (default: the study's `results`)
#   --cache DIR        dataset cache (default: the study's `cache`)
#   --rerun            run jobs that are done too
#   --no-report        do not write the report at the end (e.g. when other hosts still run)
# Everything after `--` goes to parallel (e.g. --joblog FILE --retries 2).
# Exits 1 if a job failed (the report lists it), 2 on a usage error.
set -euo pipefail

here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
usage() { sed -n '2,20p' "${BASH_SOURCE[0]}" | sed 's/^# \{0,1\}//' >&2; exit 2; }

jobs="" sshlogin="" wheelins="" study="" report=1
common=() run_extra=() parallel_extra=()
while [ $# -gt 0 ]; do
  case $1 in
    -j|--jobs) jobs=${2:?-j needs a number}; shift 2 ;;
    --sshlogin|-S) sshlogin=${2:?--sshlogin needs hosts}; shift 2 ;;
    --wheelins) wheelins=${2:?--wheelins needs a path}; shift 2 ;;
    --results|--cache) common+=("$1" "$(realpath -m "${2:?$1 needs a directory}")"); shift 2 ;;
    --rerun) run_extra+=(--rerun); shift ;;
    --no-report) report=0; shift ;;
    -h|--help) usage ;;
    --) shift; parallel_extra=("$@"); break ;;
    -*) echo "study-parallel: unknown option '$1'" >&2; usage ;;
    *) [ -z "$study" ] || { echo "study-parallel: one study file, got '$study' and '$1'" >&2; exit 2; }
       study=$1; shift ;;
  esac
done
[ -n "$study" ] || usage
[ -f "$study" ] || { echo "study-parallel: '$study': no such study file" >&2; exit 2; }
study=$(realpath "$study")
if [ -z "$wheelins" ]; then
  if [ -x "$here/../build/wheelins" ]; then wheelins=$here/../build/wheelins
  else wheelins=$(command -v wheelins || true); fi
fi
[ -n "$wheelins" ] && [ -x "$wheelins" ] || { echo "study-parallel: no wheelins binary (--wheelins PATH)" >&2; exit 2; }
wheelins=$(realpath "$wheelins")
command -v parallel >/dev/null ||
  { echo "study-parallel: GNU parallel is not installed (Debian: apt-get install parallel, or scripts/setup.sh)" >&2; exit 2; }

# The plan checks the study (a bad key fails here, before any job starts).
"$wheelins" study plan "$study" "${common[@]}" >/dev/null
n=$("$wheelins" study plan "$study" --count)
echo "study-parallel: $n jobs of $study${sshlogin:+ on $sshlogin}"

opts=(--halt never --line-buffer)
[ -n "$jobs" ] && opts+=(-j "$jobs")
[ -n "$sshlogin" ] && opts+=(--sshlogin "$sshlogin")
[ -t 2 ] && opts+=(--bar)
status=0
seq 0 $((n - 1)) | parallel "${opts[@]}" "${parallel_extra[@]}" \
  "$wheelins" study run "$study" --job {} --quiet "${common[@]}" "${run_extra[@]}" || status=$?

if [ "$report" = 1 ]; then
  "$wheelins" study report "$study" --quiet "${common[@]}" || status=$((status == 0 ? $? : status))
  echo "study-parallel: report in the study's results directory (report.md)"
fi
if [ "$status" -ne 0 ]; then
  echo "study-parallel: $status job(s) failed (listed in report.md; run again to retry them)" >&2
  exit 1
fi
