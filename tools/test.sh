#!/usr/bin/env bash
# Runs every test of hdVolPhoton: the core's GoogleTest suite (Release), the same suite under
# AddressSanitizer + UndefinedBehaviorSanitizer, the Python/USD tests (pytest), and the Hydra
# delegate's tests (usdrecord, usdview under Xvfb) with the OpenUSD the build found; one SKIPPED
# line only where there is neither an OpenUSD with imaging nor the prebuilt tarball (../shared/openusd).
# Expects tools/setup.sh to have run (it does not install anything itself).
set -euo pipefail
cd "$(dirname "$0")/.."
# shellcheck disable=SC1091
. .venv/bin/activate
jobs=${CMAKE_BUILD_PARALLEL_LEVEL:-$(nproc)}
status=0

echo "== core tests (Release)"
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build build -j "$jobs"
ctest --test-dir build --output-on-failure -j "$jobs" || status=1

if [ -z "${VOLPHOTON_SKIP_SANITIZERS:-}" ]; then
  echo "== core tests under ASan + UBSan"
  cmake -S . -B build-asan -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DVOLPHOTON_SANITIZE=ON -DVOLPHOTON_BUILD_HYDRA=OFF >/dev/null
  cmake --build build-asan -j "$jobs" --target volphotonCoreTests
  ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
    ctest --test-dir build-asan --output-on-failure -j "$jobs" || status=1
fi

echo "== Python and USD tests"
python -m pytest testenv -q --ignore=testenv/hydra || status=1

echo "== Hydra delegate"
# The OpenUSD the build found (its pxrConfig.cmake folder is the install root); its bin/ holds
# usdrecord and usdview, put first on PATH for the Hydra tests.
pxr_root=$(sed -n 's/^pxr_DIR:[A-Z]*=//p' build/CMakeCache.txt 2>/dev/null)  # PATH, or UNINITIALIZED when given by -D without a type
openusd_tarball=$(cd .. && pwd)/shared/openusd/openusd-24.08-debian12-x86_64.tar.xz
if [ -n "$pxr_root" ] && [[ "$pxr_root" != *-NOTFOUND ]] && [ -f build/hdVolPhoton/hd/hdVolPhoton.so ]; then
  if [ -x "$pxr_root/bin/usdrecord" ]; then
    PATH="$pxr_root/bin:$PATH" python -m pytest testenv/hydra -q || status=1
  else
    echo "FAILED hdVolPhoton Hydra tests: the build found OpenUSD at $pxr_root, which has no bin/usdrecord (build it with Python, imaging and usdImaging)"
    status=1
  fi
elif [ -f "$openusd_tarball" ]; then
  echo "FAILED hdVolPhoton Hydra tests: $openusd_tarball is there but the build has no Hydra delegate (run tools/setup.sh)"
  status=1
else
  echo "SKIPPED hdVolPhoton Hydra tests: no OpenUSD >= 24.08 with imaging (find_package(pxr CONFIG) found none) and no $openusd_tarball"
fi

exit $status
