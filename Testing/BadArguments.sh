#!/usr/bin/env bash
# A command-line tool with bad arguments: each line of CASES must end with status 2 and
# a message on stderr containing MESSAGE, before any window opens or any render starts.
#   BadArguments.sh TOOL "MESSAGE" CASES [FIRST ARGUMENTS...]
set -u
tool="$1"
expected="$2"
cases="$3"
shift 3
status=0
while read -r -a args; do
  message="$("$tool" "$@" "${args[@]}" 2>&1 >/dev/null)"
  code=$?
  if [ "$code" -ne 2 ] || [[ "$message" != *"$expected"* ]]; then
    echo "FAIL: $(basename "$tool") $* ${args[*]}: status $code, message: $message"
    status=1
  fi
done <"$cases"
exit $status
