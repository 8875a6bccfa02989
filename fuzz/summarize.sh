#!/usr/bin/env bash
# Prints the Markdown table of docs/reliability.md from the logs of run-all.sh (fuzz/work/*.log).
cd "$(dirname "$0")"
echo "| target | minutes | executions | exec/s | edges (cov) | corpus | peak RSS | slowest input | crashes, hangs, OOM |"
echo "|---|---|---|---|---|---|---|---|---|"
for t in native_json long_csv dltdv_csv labelme_json params animation animation_frames shape target path bird_model sleap_csv dlc_csv mot_txt idtracker_csv trex_npz sleap_h5; do
    log="work/$t.log"
    [ -f "$log" ] || continue
    grep -q "stat::number_of_executed_units" "$log" || continue
    secs=$(sed -n 's/.*Done [0-9]* runs in \([0-9]*\) second.*/\1/p' "$log" | tail -1)
    runs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log")
    eps=$(sed -n 's/^stat::average_exec_per_sec: *//p' "$log")
    rss=$(sed -n 's/^stat::peak_rss_mb: *//p' "$log")
    slow=$(sed -n 's/^stat::slowest_unit_time_sec: *//p' "$log")
    cov=$(grep -o 'cov: [0-9]*' "$log" | tail -1 | cut -d' ' -f2)
    corp=$(grep -o 'corp: [0-9]*/[0-9]*[a-zA-Z]*' "$log" | tail -1 | cut -d' ' -f2)
    n=$(find "artifacts/$t" -type f 2>/dev/null | wc -l)
    if [ -z "$secs" ]; then mins="stopped"; else mins=$(printf '%.1f' "$(echo "$secs / 60" | bc -l)"); fi
    printf '| `%s` | %s | %s | %s | %s | %s | %s MB | %s s | %s |\n' \
        "$t" "$mins" "$runs" "$eps" "$cov" "$corp" "$rss" "$slow" "$n"
done
