#!/usr/bin/env bash
# Runs fmusim (the Modelica Association's FMI 2.0/3.0 validator and simulator, github:modelica/fmusim)
# on every FMU it finds: `fmusim validate`, which must print nothing but its three progress lines,
# then `fmusim simulate` with default settings in each interface the FMU declares (Co-Simulation
# and Model Exchange), which must exit 0 with no message logged by the FMU and finite results up
# to the stop time; finally Co-Simulation against Model Exchange at the end time, every column
# within 1e-6 of its largest magnitude over the run. The FMI version comes from each FMU's
# modelDescription.xml (fmiVersion), so FMI 2.0 and 3.0 FMUs are told apart by what they are;
# where a model comes in both versions, its FMI 3.0 results must equal its FMI 2.0 results in
# every row. Results and logs go to target/fmusim/; prints one line per FMU and interface (and
# per model in both versions) and exits 1 on any problem.
#
# usage: FMUSIM=/path/to/fmusim tools/fmusim.sh [FMU or directory ...]
#   A directory is searched two levels deep for *.fmu; the default is target/ (target/fmu/ and
#   any other packaging directory there).
set -u
fmusim=${FMUSIM:?set FMUSIM to the fmusim executable (see docs/compatibility.md, fmusim)}
out=target/fmusim
rm -rf "$out"
mkdir -p "$out"
[ $# -gt 0 ] || set -- target
fmus=()
for arg in "$@"; do
  if [ -d "$arg" ]; then
    while IFS= read -r f; do fmus+=("$f"); done < <(find "$arg" -maxdepth 2 -name '*.fmu' -type f | sort)
  else
    fmus+=("$arg")
  fi
done
if [ ${#fmus[@]} = 0 ]; then
  echo "no FMU found in $*: run \`make fmus\`" >&2
  exit 1
fi

# "<end time> <rows> <finite> <stop reached> [<largest difference> <column>]" of a result file: the
# stop time given first ("-": none declared); with a second result file, the largest difference
# of the two at the end time relative to each column's largest magnitude over both runs.
summary() {
  python3 - "$@" <<'PY'
import csv, math, sys
def cells(x):
    # A Boolean, a number, or an FMI 3.0 array: its elements separated by spaces.
    x = x.strip()
    return [{"true": 1.0, "false": 0.0}[x.lower()]] if x.lower() in ("true", "false") else [float(v) for v in x.split()]
def load(path):
    with open(path) as f:
        rows = [r for r in csv.reader(f) if r]
    sizes = [len(cells(x)) for x in rows[1]] if len(rows) > 1 else [1] * len(rows[0])
    header = [name if n == 1 else f"{name}[{k + 1}]" for name, n in zip(rows[0], sizes) for k in range(n)]
    return header, [[v for x in r for v in cells(x)] for r in rows[1:]]
stop = sys.argv[1]
header, rows = load(sys.argv[2])
end = rows[-1][0] if rows else math.nan
finite = bool(rows) and all(math.isfinite(x) for r in rows for x in r)
reached = stop == "-" or abs(end - float(stop)) <= 1e-9 * max(1.0, abs(float(stop)))
line = f"{end:g} {len(rows)} {'yes' if finite else 'NO'} {'yes' if reached else 'NO'}"
if len(sys.argv) > 3:
    other_header, other = load(sys.argv[3])
    worst, column = 0.0, "-"
    if other_header != header or not rows or not other or end != other[-1][0]:
        worst, column = math.inf, "(columns or end times differ)"
    else:
        for i, name in enumerate(header[1:], 1):
            scale = max(abs(r[i]) for r in rows + other) or 1.0
            d = abs(rows[-1][i] - other[-1][i]) / scale
            if d > worst:
                worst, column = d, name
    line += f" {worst:.1e} {column}"
print(line)
PY
}

failed=0
printf '%-18s %-4s %-3s %9s %4s %10s %8s %6s %7s %9s %s\n' model fmi api validate rc fmuReports tEnd rows finite "cs-me" column
for fmu in "${fmus[@]}"; do
  xml=$(unzip -p "$fmu" modelDescription.xml 2>/dev/null)
  version=$(grep -o 'fmiVersion="[^"]*"' <<<"$xml" | head -1 | cut -d'"' -f2)
  model=$(basename "$fmu" .fmu)
  dir=$out/fmi${version%%.*}
  mkdir -p "$dir"
  # fmusim validate prints "Validating ZIP archive", "... model description", "... build
  # description"; anything else is a problem it found.
  "$fmusim" validate "$fmu" >"$dir/$model.validate.log" 2>&1
  validate_rc=$?
  problems=$(grep -vc 'Validating \(ZIP archive\|model description\|build description\)' "$dir/$model.validate.log")
  if [ "$validate_rc" != 0 ] || [ "$problems" != 0 ]; then
    failed=1
    printf '%-18s %-4s %-3s %9s\n' "$model" "$version" - "$problems"
    head -20 "$dir/$model.validate.log"
  fi
  ran=()
  for api in cs me; do
    tag=$([ $api = me ] && echo '<ModelExchange' || echo '<CoSimulation')
    if ! grep -q "$tag" <<<"$xml"; then
      printf '%-18s %-4s %-3s %s\n' "$model" "$version" "$api" "not declared"
      continue
    fi
    log=$dir/$model.$api.log
    result=$dir/$model.$api.csv
    rm -f "$result"
    "$fmusim" simulate --interface-type "$api" --output-file "$result" "$fmu" >"$log" 2>&1
    rc=$?
    # Without --logging-on an FMU logs only warnings and errors, and fmusim prints nothing else.
    reports=$(grep -c . "$log")
    compare=()
    [ $api = me ] && [ ${#ran[@]} = 1 ] && compare=("${ran[0]}")
    stop=$(grep -o '<DefaultExperiment[^>]*stopTime="[^"]*"' <<<"$xml" | grep -o 'stopTime="[^"]*"' | cut -d'"' -f2)
    read -r t_end rows finite reached worst column < <([ -s "$result" ] &&
      summary "${stop:--}" "$result" "${compare[@]}" || echo "- 0 NO NO")
    printf '%-18s %-4s %-3s %9s %4s %10s %8s %6s %7s %9s %s\n' "$model" "$version" "$api" "$problems" "$rc" \
      "$reports" "$t_end" "$rows" "$finite" "${worst:--}" "${column:-}"
    if [ "$rc" != 0 ] || [ "$reports" != 0 ] || [ "$finite" != yes ] || [ "$reached" != yes ] ||
       [ "${worst:-0}" = inf ] || python3 -c "import sys; sys.exit(float('${worst:-0}') <= 1e-6)"; then
      failed=1
      [ "$reached" = yes ] || echo "  stopped at t = $t_end, before the stop time ${stop:-}"
      head -5 "$log"
    fi
    ran+=("$result")
  done
done
# The same model in both FMI versions: every row of every column the two results share, FMI 3.0
# against FMI 2.0 (Booleans parsed: fmusim prints them as true/false for 3.0, 0/1 for 2.0).
pairs=()
for result in "$out"/fmi3/*.csv; do
  [ -f "$result" ] && [ -f "$out/fmi2/$(basename "$result")" ] && pairs+=("$result")
done
if [ ${#pairs[@]} -gt 0 ]; then
  echo
  printf '%-18s %-3s %6s %8s %s\n' model api rows columns "FMI 3.0 against FMI 2.0"
  for result in "${pairs[@]}"; do
    name=$(basename "$result" .csv)
    python3 - "$result" "$out/fmi2/$name.csv" "${name%.*}" "${name##*.}" <<'PY' || failed=1
import csv, math, sys
def cells(x):
    # A Boolean, a number, or an FMI 3.0 array (its elements separated by spaces: FMI 2.0 has no
    # arrays, so they are never among the shared columns).
    x = x.strip()
    return [{"true": 1.0, "false": 0.0}[x.lower()]] if x.lower() in ("true", "false") else [float(v) for v in x.split()]
def load(path):
    with open(path) as f:
        rows = [r for r in csv.reader(f) if r]
    table = [[cells(x) for x in r] for r in rows[1:]]
    columns = {}
    for i, name in enumerate(rows[0]):
        n = len(table[0][i]) if table else 1
        for k in range(n):
            columns[name if n == 1 else f"{name}[{k + 1}]"] = [r[i][k] for r in table]
    return columns
three, two = load(sys.argv[1]), load(sys.argv[2])
shared = [name for name in three if name in two]
rows = len(three["time"])
if len(two["time"]) != rows:
    verdict, ok = f"row counts differ ({rows} against {len(two['time'])})", False
else:
    scale = {name: max(abs(x) for x in two[name]) or 1.0 for name in shared}
    worst = max((abs(a - b) / scale[name]
                 for name in shared for a, b in zip(three[name], two[name])), default=0.0)
    identical = all(three[name] == two[name] for name in shared)
    verdict, ok = ("identical" if identical else f"largest difference {worst:.1e} of the column's range"), identical
print(f"{sys.argv[3]:<18} {sys.argv[4]:<3} {rows:>6} {len(shared) - 1:>8} {verdict}")
sys.exit(0 if ok else 1)
PY
  done
fi
exit $failed
