#!/bin/sh
# CPU seconds of test files, one pytest process each (-n 0; a waited-for subprocess's CPU counts
# in the parent's user time), with the machine's load before each: `sh benchmarks/test_file_cpu.sh
# tests/test_hostile_fuzz.py tests/test_output_safety.py ...` (default: the issue-28 item-5 files
# of the signal/output/fuzz speed-up). Compare files before/after a change in the same session.
cd "$(dirname "$0")/.." || exit 1
[ $# -gt 0 ] || set -- tests/test_hostile_fuzz.py tests/test_output_safety.py tests/test_install.py \
    tests/test_fmu.py tests/test_hostile.py tests/test_fuzz_inputs.py
for f in "$@"; do
    printf '%s  %s\n' "$f" "$(uptime | sed 's/.*load/load/')"
    /usr/bin/time -f "  %e s wall %U s user %S s sys" .venv/bin/python -m pytest -q -p no:cacheprovider -n 0 "$f" \
        2>&1 | tail -2
done
