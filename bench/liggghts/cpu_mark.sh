#!/bin/sh
# Appends the CPU time (user + system) of the LIGGGHTS process that runs this script, in clock ticks, to FILE:
# in.silo3d calls it (LIGGGHTS's `shell` command) just before and just after its timed run, so that
# bench/compare_liggghts.sh can read the run's CPU time beside its wall-clock "Loop time".
#   cpu_mark.sh FILE
p=$PPID
while [ "$p" -gt 1 ] && [ "$(cat "/proc/$p/comm")" != liggghts ]; do
    p=$(awk '{ print $4 }' "/proc/$p/stat")
done
[ "$p" -gt 1 ] || exit 1
awk '{ print $14 + $15 }' "/proc/$p/stat" >> "$1"
