#!/bin/bash
# Bundles fieldpath and test_field (built with CUDA) with their libraries for the GPU machine,
# which has no OpenVDB (BUILD-NOTES.md): bench/field/gpu_bundle.sh BUILD_DIR OUT_DIR -> OUT_DIR/fp.tar.xz
# OLD=PROGRAM: another fieldpath (the build of before issue 15) travels too, as fieldpath_old.
set -eu
build=$1
out=$2
rm -rf "$out/B" && mkdir -p "$out/B/lib"
cp "$build/bin/fieldpath" "$build/bin/test_field" "$out/B/"
# the Z-buffer's CUDA tests too (both modules' .cu files share common/cuda_check.h)
[ -x "$build/bin/test_zbuffer_cuda" ] && cp "$build/bin/test_zbuffer_cuda" "$out/B/"
[ -n "${OLD:-}" ] && cp "$OLD" "$out/B/fieldpath_old"
for l in $(ldd "$out/B/"fieldpath* "$out/B/"test_* | awk '{print $3}' | grep -E '^/' | sort -u |
           grep -vE 'libc\.so|libm\.so|libdl|libpthread|librt|ld-linux|libgcc_s|libstdc\+\+'); do
  cp -L "$l" "$out/B/lib/"
done
strip "$out/B/"fieldpath* "$out/B/"test_* "$out/B/lib/"* 2>/dev/null || true
tar -C "$out" -cJf "$out/fp.tar.xz" B
rm -rf "$out/B"  # only the tarball travels (carry counts every file of the folder)
ls -la "$out/fp.tar.xz"
