#!/usr/bin/env bash
# Jitter of the firmware loop next to cyclictest (docs/realtime.md), with the same SCHED_FIFO
# priority and CPU: first idle, then under a stress-ng CPU + memory load. The loop runs the
# Walker3 controller against the MuJoCo plant process (shared-memory backend); the plant runs on
# another CPU one priority below. Needs root (or CAP_SYS_NICE + RLIMIT_MEMLOCK) for real-time
# figures; without it everything runs and the loop's figures are marked NOT RT.
#   scripts/rt_measure.sh [BUILD_DIR=build] [SECONDS=30] [OUT_DIR=out/rt]
# Needs: scripts/setup.sh --rt (cyclictest, stress-ng); targets hqp_rt_loop and hqp_rt_plant.
set -euo pipefail
build=${1:-build}
secs=${2:-30}
out=${3:-out/rt}
prio=80
cpu_loop=1
cpu_plant=0
ticks=$((secs * 1000))
mkdir -p "$out"

run() {  # $1: label (idle / loaded)
  local l=$1
  # Load average, and the CPUs' steal time (jiffies the hypervisor ran something else).
  { date -u; uptime; grep -E '^cpu[0-9]' /proc/stat; } > "$out/load_$l.txt"
  cyclictest -m -p $prio -a $cpu_loop -i 1000 -l $ticks -q -h 2000 --histfile="$out/cyclictest_$l.hist" \
    > "$out/cyclictest_$l.txt"
  "$build/sim_demo/hqp_rt_plant" --shm /hqp_rt_measure --cpu $cpu_plant --priority $((prio - 1)) \
    > "$out/plant_$l.txt" 2>&1 &
  local plant=$!
  "$build/firmware/hqp_rt_loop" --backend shm --shm /hqp_rt_measure --ticks $ticks --priority $prio \
    --cpu $cpu_loop --out "$out/loop_$l" 2>&1 | tee "$out/loop_$l.txt"
  wait $plant
  { uptime; grep -E '^cpu[0-9]' /proc/stat; } >> "$out/load_$l.txt"
}

run idle
# CPU and memory load on both cores: 2 CPU workers + 1 VM worker cycling 256 MB.
stress-ng --cpu 2 --vm 1 --vm-bytes 256M --timeout $((2 * secs + 60))s > "$out/stress.txt" 2>&1 &
stress=$!
sleep 3
run loaded
kill $stress 2>/dev/null || true
wait $stress 2>/dev/null || true

/usr/bin/python3 firmware/plot_latency.py "$out/rt_latency.png" \
  idle="$out/loop_idle/rt_ticks.csv" loaded="$out/loop_loaded/rt_ticks.csv" \
  --cyclictest idle="$out/cyclictest_idle.hist" loaded="$out/cyclictest_loaded.hist" | tee "$out/table.md"
cat "$out"/load_*.txt
