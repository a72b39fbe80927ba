# Sourced by scripts/ros-setup.sh: builds run beside each other, which end with the script.
# Each job gets its own process group (job control is on only while it starts), so ending a
# job ends all it started (cmake, make, the generators). The EXIT trap ends the jobs still
# running however the script ends: a failure, a signal to the script alone, or one to its
# whole group. The script waits for its jobs with `wait`, which a trapped signal interrupts at
# once (a foreground command would hold the trap until it ended).
JOBS=()

# background CMD ARGS...: CMD (a function or a program) as a job; its pid is in $!.
background() {
  set -m
  "$@" </dev/null &
  set +m
  JOBS+=("$!")
}

end_jobs() {
  local pid
  for pid in "${JOBS[@]}"; do
    kill -TERM -- "-$pid" 2>/dev/null || true
  done
}

trap end_jobs EXIT
trap 'exit 129' HUP
trap 'exit 130' INT
trap 'exit 143' TERM
