#!/bin/bash
# Huge pages A/B on the GPU machine (issue 15: the refinement's host work is page-fault bound):
# FIELDPATH_HUGE_PAGES=0 (every array in 4 KiB pages) against the default (the build's large
# arrays madvised to huge pages, field/src/huge_pages.h), each also with glibc's malloc in huge
# pages (GLIBC_TUNABLES=glibc.malloc.hugetlb=1: the OpenVDB leaves too). Page faults and peak RSS
# from /usr/bin/time where the machine has it.
#   bench/field/alloc_ab.sh OUTDIR   (from the repository root, with .gpu/fp.tar.xz: gpu_bundle.sh)
set -u
out=$1
tar -C /tmp -xJf .gpu/fp.tar.xz
export LD_LIBRARY_PATH=/tmp/B/lib
fp=/tmp/B/fieldpath
T=(); [ -x /usr/bin/time ] && T=(/usr/bin/time -f "faults %R rss %M KB")
echo "THP: $(cat /sys/kernel/mm/transparent_hugepage/enabled) $(cat /sys/kernel/mm/transparent_hugepage/defrag); $(ldd --version | head -1); cores $(nproc)"
sed -e "s/sample_step: 1.0 /sample_step: 0.5 /" -e "s/refine_tolerance: 0 /refine_tolerance: 0.005 /" examples/impeller/scene.yaml > examples/impeller/.g_r.yaml
cp examples/impeller/scene.yaml examples/impeller/.g_u.yaml
for sc in .g_u .g_r; do for b in cuda cpu; do
for rep in 1 2 3 4; do for mode in none ours glibc both; do
  case $mode in
    none) e=(env FIELDPATH_HUGE_PAGES=0);;
    ours) e=(env);;
    glibc) e=(env FIELDPATH_HUGE_PAGES=0 GLIBC_TUNABLES=glibc.malloc.hugetlb=1);;
    both) e=(env GLIBC_TUNABLES=glibc.malloc.hugetlb=1);;
  esac
  r=$( { "${T[@]}" "${e[@]}" $fp --quiet field build examples/impeller/$sc.yaml --backend $b --voxel 0.5 --out /tmp/f.vdb; } 2>&1 | grep -E "time:|faults" | tr '\n' ' ')
  echo "$sc $b $mode $rep: $r"
done; done; done; done | tee $out/alloc.log | sed -E 's/time: sampling [0-9.]+ s, //'
rm -f examples/impeller/.g_[ur].yaml
