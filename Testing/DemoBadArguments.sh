#!/usr/bin/env bash
# nimbus-demo with bad arguments: each must end with status 2 and a message on stderr,
# before any window opens (so no display is needed).
#   DemoBadArguments.sh <path to nimbus-demo>
set -u
demo="$1"
status=0
while read -r -a args; do
  message="$("$demo" --output /dev/null "${args[@]}" 2>&1 >/dev/null)"
  code=$?
  if [ "$code" -ne 2 ] || [[ "$message" != *"bad or incomplete argument"* ]]; then
    echo "FAIL: nimbus-demo ${args[*]}: status $code, message: $message"
    status=1
  fi
done <<'CASES'
--size -5 10
--size 0 0
--size 1e9 16
--size abc 3
--sun-elevation nan
--sun-elevation 91
--sun-azimuth 1e308
--seed 99999999999999999999
--seed 1.5
--k-multi -1
--k-multi nan
--exposure inf
--exposure 1e308
--bogus
--size
CASES
exit $status
