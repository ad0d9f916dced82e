#!/usr/bin/env bash
# Workspace sizes on the Cortex-M4F build, for docs/embedded.md. The firmware cannot run
# here (no board, no emulator), so the size functions run on the host, built from the same
# sources in single precision, and each result is moved to the target by one term: every
# array in a workspace is of fixed-width or coa_real_t elements (the same bytes on both),
# only the header struct (pointers, size_t) differs, and its ARM size is read from the
# ARM objects' debug information. Usage: embedded_sizes.sh ARM_BUILD_DIR (a tree built
# with cmake/arm-none-eabi-cortex-m4f.cmake, RelWithDebInfo or Debug for -g).
set -euo pipefail
arm=${1:?usage: embedded_sizes.sh ARM_BUILD_DIR}
src=$(cd "$(dirname "$0")/.." && pwd)
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

struct_size() { # READELF OBJECT STRUCT
  "$1" --debug-dump=info "$2" | grep -A3 "DW_AT_name.*: $3\$" |
    sed -n 's/.*DW_AT_byte_size *: *//p' | head -n 1
}
objs=$arm/CMakeFiles/coavoid_core.dir/src/core
arm_planner=$(struct_size arm-none-eabi-readelf "$objs/plan.c.obj" coa_planner)
arm_predictor=$(struct_size arm-none-eabi-readelf "$objs/predict.c.obj" coa_predictor)

for f in common geometry trajectory plan predict; do
  cc -std=c11 -g -O1 -DCOA_SINGLE_PRECISION -I"$src/include" -c "$src/src/core/$f.c" -o "$work/$f.o"
done
host_planner=$(struct_size readelf "$work/plan.o" coa_planner)
host_predictor=$(struct_size readelf "$work/predict.o" coa_predictor)
[ -n "$arm_planner" ] && [ -n "$arm_predictor" ] && [ -n "$host_planner" ] && [ -n "$host_predictor" ] ||
  { echo "embedded_sizes: header sizes not found (built without -g?)" >&2; exit 1; }

cat > "$work/sizes.c" <<'C'
#include <stdio.h>
#include <stdlib.h>
#include "coavoid/coavoid.h"
static size_t round8(size_t a) { return (a + 7u) / 8u * 8u; }
int main(int argc, char **argv)
{
    size_t hp = strtoul(argv[1], NULL, 10), ap = strtoul(argv[2], NULL, 10);
    size_t hq = strtoul(argv[3], NULL, 10), aq = strtoul(argv[4], NULL, 10);
    static const struct { size_t n; uint32_t beta; } pl[] = {
        {1, 24}, {1, 100}, {1, 300}, {1, 1000}, {1, 10000},
        {2, 50}, {2, 200}, {2, 1000}, {3, 20}, {3, 100}, {3, 1000}};
    static const struct { size_t v, t; uint32_t n; } pr[] = {
        {4, 0, 24}, {8, 0, 24}, {16, 0, 24}, {8, 2, 24}, {4, 0, 60}, {8, 0, 60}, {16, 0, 60}};
    size_t i;
    (void)argc;
    printf("planner: n, beta, host (x86-64, float) bytes, Cortex-M4F bytes, per closed node\n");
    for (i = 0; i < sizeof pl / sizeof pl[0]; ++i) {
        size_t h = coa_planner_workspace_size(pl[i].n, pl[i].beta);
        size_t a = h - round8(hp) + round8(ap);
        printf("%zu %u %zu %zu %.0f\n", pl[i].n, pl[i].beta, h, a,
               (double)(a - round8(ap)) / pl[i].beta);
    }
    printf("predictor: UAVs, tracks, N, pairs (4 per UAV), host bytes, Cortex-M4F bytes\n");
    for (i = 0; i < sizeof pr / sizeof pr[0]; ++i) {
        size_t h = coa_predictor_workspace_size(pr[i].v, pr[i].t, pr[i].n, 4u * pr[i].v);
        printf("%zu %zu %u %zu %zu %zu\n", pr[i].v, pr[i].t, pr[i].n, 4u * pr[i].v, h,
               h - round8(hq) + round8(aq));
    }
    printf("headers: planner host %zu ARM %zu; predictor host %zu ARM %zu\n", hp, ap, hq, aq);
    /* The ARM header is smaller: the same buffer holds what the host's would with
     * that much more room. */
    printf("firmware planner buffer 96 KiB: beta %u on the host, %u on the Cortex-M4F\n",
           coa_planner_max_beta(1u, 96u * 1024u),
           coa_planner_max_beta(1u, 96u * 1024u + round8(hp) - round8(ap)));
    return 0;
}
C
cc -std=c11 -DCOA_SINGLE_PRECISION -I"$src/include" "$work/sizes.c" "$work"/{common,geometry,trajectory,plan,predict}.o \
  -lccd -lm -o "$work/sizes"
"$work/sizes" "$host_planner" "$arm_planner" "$host_predictor" "$arm_predictor"
