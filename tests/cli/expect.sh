# tests/cli/expect.sh -- sourced by the CLI scripts (cli_bad_input.sh, cli_bad_data.sh):
# runs vrelab and counts what held. Expects $bin (the program) and $tmp (a scratch folder).
fail=0
pass=0

expect() {  # expect <want rc> <stdout/stderr regex> <args...>
  local want=$1 pattern=$2
  shift 2
  "$bin" "$@" >"$tmp/out" 2>"$tmp/err"
  local rc=$?
  if [ "$rc" -ne "$want" ] || ! grep -Eq -- "$pattern" "$tmp/err" "$tmp/out"; then
    echo "FAIL: vrelab $* -> rc $rc (want $want), stderr: $(tail -c 600 "$tmp/err")"
    fail=$((fail + 1))
  else
    pass=$((pass + 1))
  fi
}

check() {  # check <description> <command...>: a condition that must hold
  local what=$1
  shift
  if "$@"; then pass=$((pass + 1)); else echo "FAIL: $what"; fail=$((fail + 1)); fi
}
