#!/usr/bin/env bash
# The peer figure beside bench_bbm's: Debian's Yade (2023.02a on Debian 12) running
# its JCFpm bonded-sphere model (bench/yade_jcfpm.py) on 1 and 2 threads, on this
# machine. Installs yade if it is missing (root or sudo). Prints one line per
# thread count, and writes them as JSON to the file given (default yade_peer.json).
set -euo pipefail
cd "$(dirname "$0")/.."
out=${1:-yade_peer.json}
if ! command -v yade >/dev/null; then
    as_root=(); [ "$(id -u)" -eq 0 ] || as_root=(sudo)
    "${as_root[@]}" apt-get update
    DEBIAN_FRONTEND=noninteractive "${as_root[@]}" apt-get install -y --no-install-recommends yade
fi
lines=()
for threads in 1 2; do
    line=$(yade -j "$threads" -n -x bench/yade_jcfpm.py 2>/dev/null | grep '^yade-jcfpm')
    echo "$line"
    lines+=("$line")
done
{
    echo '{"benchmark": "yade_jcfpm_peer", "runs": ['
    for k in "${!lines[@]}"; do
        set -- ${lines[$k]}
        printf '  {"particles": %s, "contacts": %s, "threads": %s, "steps": %s, "seconds": %s, "contact_updates_per_second": %s}' \
            "$3" "$5" "$7" "$9" "${11}" "${13}"
        [ "$k" -lt $((${#lines[@]} - 1)) ] && echo ',' || echo
    done
    echo ']}'
} > "$out"
echo "wrote $out"
