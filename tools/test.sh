#!/usr/bin/env bash
# Runs every test of hdVolPhoton: the core's GoogleTest suite (Release), the same suite under
# AddressSanitizer + UndefinedBehaviorSanitizer, the Python/USD tests (pytest), and the Hydra
# delegate's tests where an OpenUSD build with imaging exists (else one SKIPPED line).
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
if grep -q "^pxr_DIR:PATH=.*-NOTFOUND" build/CMakeCache.txt 2>/dev/null || ! grep -q "^pxr_DIR:PATH=" build/CMakeCache.txt 2>/dev/null; then
  echo "SKIPPED hdVolPhoton Hydra tests: no OpenUSD >= 24.08 with imaging (find_package(pxr CONFIG) found none)"
elif ! command -v usdrecord >/dev/null; then
  echo "SKIPPED hdVolPhoton Hydra tests: OpenUSD found but usdrecord is not on PATH"
else
  python -m pytest testenv/hydra -q || status=1
fi

exit $status
