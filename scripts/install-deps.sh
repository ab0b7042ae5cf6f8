#!/usr/bin/env bash
# install-deps.sh: installs the Debian 12 packages that building, testing and
# plotting need; idempotent.  Every requirement is probed first (dpkg -s, or
# the header, library or program itself); when all are present, apt is not
# touched, so this works offline on a prepared machine.  Otherwise it runs
# apt-get update and apt-get install -y --no-install-recommends on the missing
# packages, through sudo when not root.
#   MBCC_DEPS_FORCE=1  run apt even when everything is present
set -euo pipefail

# can the C compiler link against library $1?
links() {
  command -v cc >/dev/null 2>&1 || return 1
  local out
  out=$(mktemp)
  if echo 'int main(void) { return 0; }' | cc -x c - "-l$1" -o "$out" >/dev/null 2>&1; then
    rm -f "$out"; return 0
  fi
  rm -f "$out"; return 1
}

# the requirement that package $1 provides is met
present() {
  if dpkg -s "$1" >/dev/null 2>&1; then
    # installed; for gnuplot, also the PNG terminal the plots use
    [ "$1" != gnuplot-nox ] || gnuplot -e 'set terminal pngcairo' >/dev/null 2>&1
    return
  fi
  case $1 in
    build-essential)    command -v cc && command -v make && command -v g++ && [ -e /usr/include/stdio.h ] ;;
    libyaml-dev)        [ -e /usr/include/yaml.h ] && links yaml ;;
    libsuitesparse-dev) [ -e /usr/include/suitesparse/klu.h ] && links klu &&
                        [ -e /usr/include/suitesparse/cholmod.h ] && links cholmod &&
                        [ -e /usr/include/suitesparse/SuiteSparseQR_C.h ] && links spqr ;;
    liblapack-dev)      links lapack ;;
    libblas-dev)        links blas ;;
    libcmocka-dev)      [ -e /usr/include/cmocka.h ] && links cmocka ;;
    libarpack2-dev)     links arpack ;;
    libsundials-dev)    [ -e /usr/include/ida/ida.h ] && links sundials_ida && links sundials_nvecserial &&
                        [ -e /usr/include/sunlinsol/sunlinsol_klu.h ] && links sundials_sunlinsolklu &&
                        links sundials_sunmatrixsparse ;;
    libmujoco-dev)      [ -e /usr/include/mujoco/mujoco.h ] && links mujoco ;;
    python3-yaml)       python3 -c 'import yaml' ;;
    valgrind)           command -v valgrind ;;
    gnuplot-nox)        gnuplot -e 'set terminal pngcairo' ;;
    clang)              command -v clang ;;
    nodejs)             command -v node ;;
    npm)                command -v npm ;;
    chromium)           command -v chromium ;;
    gcc-arm-none-eabi)  command -v arm-none-eabi-gcc ;;
    libnewlib-arm-none-eabi) [ -e /usr/lib/arm-none-eabi/newlib/thumb/v7e-m+fp/hard/libm.a ] ;;
    qemu-system-arm)    command -v qemu-system-arm ;;
    pkgconf)            command -v pkg-config ;;
    libclang-rt-14-dev) [ -e "$(clang -print-file-name=libclang_rt.fuzzer-x86_64.a)" ] ;; # make fuzz
    time)               [ -x /usr/bin/time ] ;;
    python3)            command -v python3 ;;
    parallel)           parallel --version | grep -q 'GNU parallel' ;;
    openssh-server)     [ -x /usr/sbin/sshd ] ;;
    openssh-client)     command -v ssh && command -v ssh-keygen ;;
    *)                  false ;;
  esac >/dev/null 2>&1
}

# gnuplot-nox has the pngcairo terminal on Debian 12 (checked: 5.4.4).
# nodejs and npm build the animation player (make web: three.js, esbuild);
# chromium plays the pages in make test-browser.  A Node.js installed some
# other way (with its own npm) counts as present.  The embedded target's cross
# compiler, newlib (libm) and qemu (tests/test_embedded.sh): 97 MB to download,
# 924 MB installed, about 2 minutes of apt (measured).  pkgconf (pkg-config)
# for tests/test_install.sh; libclang-rt-14-dev (libFuzzer) for make fuzz;
# time (/usr/bin/time, peak memory) for make scaling; python3 (the standard
# library only) for make chassis and tests/test_chassis.sh; GNU parallel runs
# the variants of mbcc sweep (tests/test_sweep.sh), which also runs them over
# ssh to a private sshd on localhost (openssh-server, openssh-client; the
# service itself is not needed).  make bench's peers: SUNDIALS IDA with KLU
# (libsundials-dev's sunlinsol_klu and sparse matrix), MuJoCo 2.2 (libmujoco-dev,
# the mj_forward peer, scripts/peers.sh), python3-yaml (scripts/mjcf_from_yaml.py
# reads the model) and valgrind (cachegrind's instruction counts).
packages=(build-essential libyaml-dev libsuitesparse-dev liblapack-dev libblas-dev
          libcmocka-dev libsundials-dev libarpack2-dev gnuplot-nox clang nodejs npm chromium
          gcc-arm-none-eabi libnewlib-arm-none-eabi qemu-system-arm pkgconf libclang-rt-14-dev time python3
          parallel openssh-server openssh-client libmujoco-dev python3-yaml valgrind)
missing=()
for p in "${packages[@]}"; do
  present "$p" || missing+=("$p")
done

if [ ${#missing[@]} -eq 0 ] && [ "${MBCC_DEPS_FORCE:-0}" != 1 ]; then
  echo "install-deps: all dependencies present"
  exit 0
fi
[ ${#missing[@]} -eq 0 ] && missing=("${packages[@]}")

if ! command -v apt-get >/dev/null 2>&1; then
  echo "install-deps: error: missing ${missing[*]}, and apt-get is not available" \
       "(this script is for Debian 12; install the equivalents by hand)" >&2
  exit 1
fi
sudo=()
if [ "$(id -u)" != 0 ]; then
  if ! command -v sudo >/dev/null 2>&1; then
    echo "install-deps: error: missing ${missing[*]}; run this script as root or install sudo" >&2
    exit 1
  fi
  sudo=(sudo)
fi

echo "install-deps: installing ${missing[*]}"
"${sudo[@]}" env DEBIAN_FRONTEND=noninteractive apt-get update
"${sudo[@]}" env DEBIAN_FRONTEND=noninteractive \
  apt-get install -y --no-install-recommends "${missing[@]}"

# check that what was installed does what we need
failed=()
for p in "${packages[@]}"; do
  present "$p" || failed+=("$p")
done
if [ ${#failed[@]} -ne 0 ]; then
  echo "install-deps: error: still missing after apt-get: ${failed[*]}" >&2
  exit 1
fi
echo "install-deps: all dependencies present"
