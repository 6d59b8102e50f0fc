#!/usr/bin/env bash
# Would a fresh Debian 12 machine have everything this build used? A machine
# that has built the project for a while carries packages the install script
# never named (a -dev package pulled in by hand, or by the image), and a
# green CI there proves nothing for a new user. This maps what the build and
# its tests use to Debian packages and checks each is in the install script's
# dependency closure without Recommends (the script installs with
# --no-install-recommends):
#   - every path under /usr that BUILD/CMakeCache.txt records: package config
#     folders (Qt5OpenGL_DIR, ...), libraries, include folders, programs;
#   - every shared library the project's own binaries and modules load (ldd);
#   - every Python module the tests and the `octoray` package import, as
#     /usr/bin/python3 finds it.
#   scripts/check-fresh-deps.sh [BUILD] [INSTALL_SCRIPT]
# Exit 1 with one line per package outside the closure (and what used it);
# exit 0 with a count. Run by `make test` as the test `deps.fresh-machine`.
set -uo pipefail
top=$(cd "$(dirname "$0")/.." && pwd)
build=${1:-$top/build}
script=${2:-$top/scripts/install-deps.sh}
cache=$build/CMakeCache.txt
[ -f "$cache" ] || { echo "check-fresh-deps: no $cache (configure first)"; exit 2; }

# ---- What a fresh machine has: the packages of priority required (every
# Debian system has them), what the install script names, and everything
# those bring along.
named=$(sed -n '/^packages=(/,/^)/p' "$script" | sed 's/#.*//' | tr -s ' \t' '\n' |
  grep -E '^[a-z0-9][a-z0-9.+-]+$' | sort -u)
[ -n "$named" ] || { echo "check-fresh-deps: no packages=( ... ) list in $script"; exit 2; }
required=$(dpkg-query -W -f='${Package} ${Priority} ${Essential}\n' | awk '$2 == "required" || $3 == "yes" { print $1 }')
# apt-cache prints virtual packages as <name>; their providers follow on the
# next lines, so dropping the brackets keeps both.
closure=$(apt-cache depends --recurse --no-recommends --no-suggests --no-conflicts --no-breaks \
  --no-replaces --no-enhances $named $required 2>/dev/null |
  sed -E 's/^ *\|?(Pre)?Depends: *//; s/^ +//; s/[<>]//g; s/:.*$//' | grep -E '^[a-z0-9][a-z0-9.+-]+$' | sort -u)

# ---- What the build used: "path<TAB>what used it" lines.
used=$(
  # CMake's cache: found packages, libraries, headers and programs.
  grep -E '^[A-Za-z0-9_.+-]+:(PATH|FILEPATH|STRING|INTERNAL)=/usr/' "$cache" |
    sed -E 's/^([^:]+):[A-Z]+=(.*)$/\2\t\1/' |
    awk -F'\t' '{ n = split($1, p, ";"); for (i = 1; i <= n; ++i) if (p[i] ~ /^\/usr\//) print p[i] "\t" $2 }'
  # Shared libraries of the project's binaries and modules.
  find "$build/bin" "$build/lib" -maxdepth 1 -type f \( -perm -u+x -o -name '*.so*' \) 2>/dev/null |
    while read -r f; do
      ldd "$f" 2>/dev/null | awk -v f="${f##*/}" '$3 ~ /^\// { print $3 "\tldd " f }'
    done
  # Python modules the tests and the package import.
  modules=$(grep -rhoE '^\s*(import|from) [A-Za-z_][A-Za-z0-9_]*' "$top/Testing" "$top/Wrapping" 2>/dev/null |
    awk '{ print $2 }' | sort -u)
  /usr/bin/python3 - $modules <<'PY' 2>/dev/null
import importlib.util, sys
for name in sys.argv[1:]:
    try:
        spec = importlib.util.find_spec(name)
    except Exception:
        continue
    origin = spec.origin if spec else None
    if origin and origin.startswith("/usr/"):
        print(f"{origin}\tpython import {name}")
PY
)

# ---- Map each path to the packages that own it, in one dpkg call. A path
# owned by several packages (a shared folder) is there when any one of them
# is installed.
declare -A why=()
while IFS=$'\t' read -r path what; do
  [ -e "$path" ] || continue
  case $path in /usr/local/*) continue ;; esac
  why[$(realpath "$path")]=$what
done <<<"$used"
missing=0
declare -A reported=() checked=()
while IFS= read -r line; do
  owners=${line%%: /*}; path=${line#*: }
  ok=0
  for p in ${owners//,/ }; do
    p=${p%%:*}
    checked[$p]=1
    grep -qx "$p" <<<"$closure" && ok=1
  done
  if [ "$ok" = 0 ] && [ -z "${reported[$owners]:-}" ]; then
    reported[$owners]=1
    echo "not installed on a fresh machine: ${owners//, / or } (used by ${why[$path]:-the build}: $path)"
    missing=$((missing + 1))
  fi
done < <(dpkg -S "${!why[@]}" 2>/dev/null | grep -v '^diversion')
if [ "$missing" -gt 0 ]; then
  echo "check-fresh-deps: $missing package(s) missing from $script's packages=( ... )"
  exit 1
fi
echo "check-fresh-deps: all ${#why[@]} paths the build and its tests use (owned by ${#checked[@]} packages) are on a fresh machine after the install script"
