# shellcheck shell=bash
# Shared by scripts/slurm/up and down (sourced, not run; the caller sets `me`).

say() { echo "slurm/${me:?}: $*" >&2; }
die() { say "error: $*"; exit 1; }

# DIR as an absolute path, refusing what slurm.conf cannot hold.
absolute_dir() {
    local d
    d=$(cd "$1" && pwd)
    case $d in
        *[[:space:]\"\'\$\\\`#=]*) die "DIR '$d' has a space or a special character; slurm.conf cannot hold it" ;;
    esac
    echo "$d"
}

# A recorded process (a DIR/pids line: name pid start-time) is ours while its pid holds the same start time
# (field 22 of /proc/PID/stat), so a recycled pid is never mistaken for it; a zombie counts as stopped.
stat_field() { [ -r "/proc/$1/stat" ] && sed 's/.*) //' "/proc/$1/stat" | cut -d' ' -f"$2"; }
start_time() { stat_field "$1" 20; }
running() { # PID START
    local now st
    now=$(start_time "$1" 2>/dev/null) || return 1
    [ "$now" = "$2" ] || return 1
    st=$(stat_field "$1" 1 2>/dev/null) || return 1
    [ "$st" != Z ] && [ "$st" != X ]
}
