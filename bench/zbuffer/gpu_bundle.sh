#!/usr/bin/env bash
# Bundles fieldpath, bench_zbuffer, bench_path_read and test_zbuffer_cuda (built here with CUDA)
# with the shared libraries ldd lists beyond the C/C++ runtime, for the GPU machine, which has no
# OpenVDB, FCL, assimp or SUNDIALS (shared BUILD-NOTES.md):
#   bench/zbuffer/gpu_bundle.sh BUILD_DIR OUT_DIR   → OUT_DIR/fp.tar.xz (unpacks to B/)
set -euo pipefail
build=$1 out=$2
bins=(fieldpath bench_zbuffer bench_path_read test_zbuffer_cuda)
rm -rf "$out/B" && mkdir -p "$out/B/lib"
for b in "${bins[@]}"; do cp "$build/bin/$b" "$out/B/"; done
for l in $(for b in "${bins[@]}"; do ldd "$build/bin/$b"; done | awk '{print $3}' | grep -E '^/' |
           sort -u | grep -vE 'libc\.so|libm\.so|libdl|libpthread|librt|ld-linux|libgcc_s|libstdc\+\+'); do
  cp -L "$l" "$out/B/lib/"
done
strip "$out/B/"* "$out/B/lib/"* 2>/dev/null || true
tar -C "$out" -cJf "$out/fp.tar.xz" B
rm -rf "$out/B"
ls -la "$out/fp.tar.xz"
