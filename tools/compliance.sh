#!/usr/bin/env bash
# Runs the FMU Compliance Checker (modelica-tools/FMUComplianceChecker, `fmuCheck.<platform>`) on
# every FMU in target/fmu: XML, then each interface the FMU declares (Model Exchange and
# Co-Simulation), driven by the cross-check inputs crosscheck/<Model>/<Model>_in.csv and the
# stop time and step of <Model>_ref.opt. Results and logs go to target/compliance/; prints one
# line per run (checker errors and warnings, FMU log messages, result rows, and the largest
# difference of the checker's result from <Model>_ref.csv relative to each column's range, and
# that column) and
# exits 1 if the checker or the FMU reported an error.
#
# usage: FMUCHECKER=/path/to/fmuCheck.linux64 tools/compliance.sh
set -u
checker=${FMUCHECKER:?set FMUCHECKER to the fmuCheck executable (see README, FMU Compliance Checker)}
out=target/compliance
mkdir -p "$out"
failed=0
# The checker's only Model Exchange solver is explicit Euler at the step -h. The motor's rotor is
# stiff (inertial time 2I/c = 4.4 ns): explicit Euler is stable only below that, so its ME run
# steps at 1 ns and writes one row per reference step (-n) instead of every step.
me_step() {
  case $1 in
    MultiferroicMotor) echo 1e-9 ;;
  esac
}
# Largest |result - reference| over each reference column's range, at the times both have
# (the checker writes every step with -n 0); columns the result lacks are skipped. The reference
# is a co-simulation, whose outputs at t are those of the inputs at t - step; algebraic Model
# Exchange outputs follow the inputs at t, so for `me` of a model without states (third argument
# 1) result(t) is compared with reference(t + step). With continuous states both interfaces give
# the states at t: compared at t (third argument 0).
compare() {
  python3 - "$1" "$2" "$3" <<'PY'
import csv, sys
def load(path):
    with open(path) as f:
        rows = list(csv.reader(f))
    names = [n.strip('"') for n in rows[0]]
    return {n: [float(r[i]) for r in rows[1:]] for i, n in enumerate(names)}
res, ref = load(sys.argv[1]), load(sys.argv[2])
step = ref["time"][1] - ref["time"][0]
shift = int(sys.argv[3])
index = {round(x / step) + shift: i for i, x in enumerate(res["time"])}
worst, column = 0.0, "-"
for name, ys in ref.items():
    if name == "time" or name not in res:
        continue
    span = max(ys) - min(ys) or max(abs(y) for y in ys) or 1.0
    for x, y in zip(ref["time"], ys):
        i = index.get(round(x / step))
        if i is not None and abs(res["time"][i] + shift * step - x) < 1e-6 * step:
            if abs(res[name][i] - y) / span > worst:
                worst, column = abs(res[name][i] - y) / span, name
print(f"{worst:.1e} {column}")
PY
}
printf '%-18s %-3s %8s %8s %10s %6s %9s %s\n' model api checkerE checkerW fmuReports rows vsRef column
for fmu in target/fmu/*.fmu; do
  model=$(basename "$fmu" .fmu)
  xml=$(unzip -p "$fmu" modelDescription.xml)
  opt=crosscheck/$model/${model}_ref.opt
  inputs=crosscheck/$model/${model}_in.csv
  args=()
  stop= step=
  if [ -f "$opt" ]; then
    stop=$(awk -F', *' '$1 == "StopTime" {print $2}' "$opt")
    step=$(awk -F', *' '$1 == "StepSize" {print $2}' "$opt")
    args+=(-s "$stop")
  fi
  [ -f "$inputs" ] && args+=(-i "$inputs")
  states=$(grep -q '<Derivatives>' <<<"$xml" && echo 1 || echo 0)
  for api in me cs; do
    steps=(-n 0)
    [ -n "$step" ] && steps+=(-h "$step")
    fine=$(me_step "$model")
    if [ $api = me ] && [ -n "$fine" ] && [ -n "$stop" ]; then
      steps=(-h "$fine" -n "$(python3 -c "print(round($stop / $step))")")
    fi
    tag=$([ $api = me ] && echo '<ModelExchange' || echo '<CoSimulation')
    if ! grep -q "$tag" <<<"$xml"; then
      printf '%-18s %-3s %s\n' "$model" "$api" "not declared"
      continue
    fi
    log=$out/$model.$api.log
    "$checker" -l 3 "${steps[@]}" -k "$api" "${args[@]}" -o "$out/$model.$api.csv" -e "$log" "$fmu" >/dev/null 2>&1
    rc=$?
    # The summary at the end of the log: "FMU reported: N warning(s) and error(s)" and
    # "Checker reported: W Warning(s) E Error(s)".
    fmu_reports=$(awk '/FMU reported:/ {getline; print $1}' "$log")
    checker_w=$(awk '/Checker reported:/ {getline; print $1}' "$log")
    checker_e=$(awk '/Checker reported:/ {getline; getline; print $1}' "$log")
    rows=$(($(wc -l <"$out/$model.$api.csv") - 1))
    ref=crosscheck/$model/${model}_ref.csv
    versus=$([ -f "$ref" ] && [ "$rows" -gt 1 ] && compare "$out/$model.$api.csv" "$ref" $([ $api = me ] && [ "$states" = 0 ] && echo 1 || echo 0) || echo -)
    printf '%-18s %-3s %8s %8s %10s %6s %9s %s\n' "$model" "$api" "${checker_e:-?}" "${checker_w:-?}" \
      "${fmu_reports:-?}" "$rows" $versus
    if [ "$rc" != 0 ] || [ "${checker_e:-1}" != 0 ] || grep -q '^\[\(ERROR\|FATAL\)' "$log"; then
      failed=1
      grep -E '^\[(ERROR|FATAL|WARNING)' "$log" | head -5
    fi
  done
done
exit $failed
