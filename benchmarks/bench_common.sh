# Shell functions of the benchmark scripts (benchmarks/*.sh), sourced after
# they set `root` (the repository) and define `usage` (their help text).

# Reads the script's arguments into its variables: `--NAME VALUE` for each
# NAME in the first word list, `--NAME` (sets NAME=1) for each in the
# second; a '-' in NAME is a '_' in the variable's name. -h or --help prints
# the usage and exits 0; any other argument is an error (exit 2).
read_options() {
  local values=" $1 " flags=" $2 " script name
  script=$(basename "$0")
  shift 2
  while [ $# -gt 0 ]; do
    name=${1#--}
    if [ "$1" = -h ] || [ "$1" = --help ]; then
      usage
      exit 0
    elif [ -n "$name" ] && [ "$1" = "--$name" ] && [[ "$values" == *" $name "* ]]; then
      printf -v "${name//-/_}" '%s' "$2"
      shift 2
    elif [ -n "$name" ] && [ "$1" = "--$name" ] && [[ "$flags" == *" $name "* ]]; then
      printf -v "${name//-/_}" '%s' 1
      shift
    else
      echo "$script: unknown argument '$1'" >&2
      usage >&2
      exit 2
    fi
  done
}

# Builds the program TARGET in build-bench (Release, CPU only; configured
# when missing, a no-op when up to date) and sets the variable VAR to its
# path: bench_program TARGET VAR.
bench_program() {
  local build="$root/build-bench"
  if [ ! -f "$build/CMakeCache.txt" ]; then
    cmake -S "$root" -B "$build" -DCMAKE_BUILD_TYPE=Release -DODEMAG_CUDA=OFF -DODEMAG_BUILD_DEMOS=OFF >/dev/null
  fi
  cmake --build "$build" -j2 --target "$1" >/dev/null
  printf -v "$2" '%s' "$build/bin/$1"
}
