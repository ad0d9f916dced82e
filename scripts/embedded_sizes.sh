#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
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
objs=$arm/src/core/CMakeFiles/coavoid_core.dir
arm_planner=$(struct_size arm-none-eabi-readelf "$objs/plan.c.obj" coa_planner)
arm_predictor=$(struct_size arm-none-eabi-readelf "$objs/predict.c.obj" coa_predictor)

# The host objects take the ARM build's COA_MAX_CENTRALISED: it sizes the header's arrays.
maxc=$(sed -n 's/^COAVOID_MAX_CENTRALISED:[A-Z]*=//p' "$arm/CMakeCache.txt")
[ -n "$maxc" ] || { echo "embedded_sizes: no COAVOID_MAX_CENTRALISED in $arm/CMakeCache.txt" >&2; exit 1; }
defs=(-DCOA_SINGLE_PRECISION "-DCOA_MAX_CENTRALISED=${maxc}u")
core="common geometry trajectory plan plan_table plan_pair plan_group plan_search predict"
for f in $core; do
  cc -std=c11 -g -O1 "${defs[@]}" -I"$src/include" -c "$src/src/core/$f.c" -o "$work/$f.o"
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
    /* N = 24 and steep factor 2 (the paper's and the firmware's), offsets unbounded. */
    static const uint32_t betas[] = {1000, 10000, 60000};
    static const struct { size_t v, t; uint32_t n; } pr[] = {
        {4, 0, 24}, {8, 0, 24}, {16, 0, 24}, {8, 2, 24}, {4, 0, 60}, {8, 0, 60}, {16, 0, 60}};
    size_t i;
    (void)argc;
    printf("planner (N 24, s 2, unbounded): n, beta, host (x86-64, float) bytes, Cortex-M4F "
           "bytes, tables, bytes per stored node\n");
    for (size_t n = 1; n <= COA_MAX_CENTRALISED; ++n) {
        for (i = 0; i < sizeof betas / sizeof betas[0]; ++i) {
            coa_planner_config_t c = {n, betas[i], 24u, 2u, -1};
            size_t h = coa_planner_workspace_size(&c);
            size_t a = h - round8(hp) + round8(ap);
            size_t tables = (n == 1u ? 1u : 2u * n + 1u) * 1225u * 8u;
            /* Per stored node: the slope over 59,000 nodes (one more node can cost up to
             * 8 bytes more than the slope: every array starts on an 8-byte boundary). */
            coa_planner_config_t lo = c, hi = c;
            lo.beta = 1000u;
            hi.beta = 60000u;
            printf("%zu %u %zu %zu %zu %.2f\n", n, betas[i], h, a, tables,
                   (double)(coa_planner_workspace_size(&hi) - coa_planner_workspace_size(&lo)) /
                       59000.0);
        }
    }
    printf("predictor: UAVs, tracks, N, pairs (4 per UAV), host bytes, Cortex-M4F bytes\n");
    for (i = 0; i < sizeof pr / sizeof pr[0]; ++i) {
        size_t h = coa_predictor_workspace_size(pr[i].v, pr[i].t, pr[i].n, 4u * pr[i].v);
        printf("%zu %zu %u %zu %zu %zu\n", pr[i].v, pr[i].t, pr[i].n, 4u * pr[i].v, h,
               h - round8(hq) + round8(aq));
    }
    printf("headers: planner host %zu ARM %zu; predictor host %zu ARM %zu\n", hp, ap, hq, aq);
    /* The ARM header is smaller: the same buffer holds what the host's would with
     * that much more room. The firmware plans one UAV (N 24, s 2, max_offset 40). */
    {
        coa_planner_config_t c = {1u, 1u, 24u, 2u, 40};
        printf("firmware planner buffer 32 KiB, n = 1: %zu bytes used on the Cortex-M4F\n",
               coa_planner_workspace_size(&c) - round8(hp) + round8(ap));
        c.vehicles = 3u;
        printf("firmware check triple (N 16, s 3, L 8), n = 3, beta 1000: %zu on the Cortex-M4F\n",
               (c.horizon = 16u, c.steep_factor = 3u, c.max_offset = 8, c.beta = 1000u,
                coa_planner_workspace_size(&c) - round8(hp) + round8(ap)));
    }
    return 0;
}
C
objs_host=(); for f in $core; do objs_host+=("$work/$f.o"); done
cc -std=c11 "${defs[@]}" -I"$src/include" "$work/sizes.c" "${objs_host[@]}" \
  -lccd -lm -o "$work/sizes"
"$work/sizes" "$host_planner" "$arm_planner" "$host_predictor" "$arm_predictor"

# The vehicle protocol (src/protocol) as the cross build sizes it: its struct from the ARM
# objects' debug information, and coavoid_vehicle_node_size's other terms (the solver:
# predictor, planner and conflicts) from the host's size functions at the ARM build's
# capacities (its -D flags), moved to the target by their headers as above.
pobjs=$arm/src/protocol/CMakeFiles/coavoid_protocol.dir
flags=$pobjs/flags.make
[ -f "$flags" ] || { echo "embedded_sizes: $flags not found (no src/protocol in the ARM build)" >&2; exit 1; }
read -r -a pdefs <<< "$(sed -n 's/^C_DEFINES = //p' "$flags")"
arm_vehicle=$(struct_size arm-none-eabi-readelf "$pobjs/vehicle.c.obj" coavoid_vehicle_node)
arm_inbox=$(struct_size arm-none-eabi-readelf "$pobjs/inbox.c.obj" coavoid_node_inbox)
[ -n "$arm_vehicle" ] && [ -n "$arm_inbox" ] ||
  { echo "embedded_sizes: the vehicle's struct size not found (built without -g?)" >&2; exit 1; }
arm_vehicle=$((arm_vehicle)) # readelf writes large sizes in hexadecimal
arm_inbox=$((arm_inbox))
cat > "$work/vehicle.c" <<'C'
#include <stdio.h>
#include <stdlib.h>
#include "protocol_internal.h"
static size_t round8(size_t a) { return (a + 7u) / 8u * 8u; }
int main(int argc, char **argv)
{
    size_t hp = strtoul(argv[1], NULL, 10), ap = strtoul(argv[2], NULL, 10);
    size_t hq = strtoul(argv[3], NULL, 10), aq = strtoul(argv[4], NULL, 10);
    size_t vehicle = strtoul(argv[5], NULL, 10), inbox = strtoul(argv[6], NULL, 10);
    const size_t n = COAVOID_NODE_MAX_PEERS;
    const size_t pairs = n * (n - 1u) / 2u + n * COAVOID_NODE_MAX_TRACKS +
                         n * COAVOID_NODE_MAX_OBSTACLES; /* coavoid_node_max_pairs */
    (void)argc;
    printf("vehicle protocol (%zu UAVs with itself, %u tracks, %u obstacles of its own), "
           "Cortex-M4F bytes:\n", n, (unsigned)COAVOID_NODE_MAX_TRACKS,
           (unsigned)COAVOID_NODE_MAX_CONFIGURED_OBSTACLES);
    printf("  node struct %zu (inbox %zu)\n", vehicle, inbox);
    static const uint32_t horizons[] = {12u, 24u};
    for (size_t h = 0; h < 2u; ++h) {
        const uint32_t N = horizons[h];
        size_t predictor = coa_predictor_workspace_size(n, COAVOID_NODE_TRACK_CAPACITY, N, pairs);
        predictor = predictor - round8(hq) + round8(aq);
        /* A decoupled vehicle's planner: one UAV over N + 2 (the order search's look-ahead),
         * the steep factor and unbounded offsets of coavoid_node_planner_config. */
        coa_planner_config_t c = {1u, 20000u, N + 2u, COAVOID_NODE_MAX_STEEP_FACTOR, -1};
        size_t planner = coa_planner_workspace_size(&c) - round8(hp) + round8(ap);
        size_t conflicts = round8(pairs * sizeof(coa_conflict_t)); /* fixed-width: 40 on both */
        /* The predictor and the planner take turns in one workspace (coavoid_node_solver_t). */
        const size_t shared = round8(predictor) > round8(planner) ? round8(predictor) : round8(planner);
        printf("  N %u: predictor %zu, one-UAV planner %zu (one workspace of %zu for both), "
               "conflicts %zu (%zu pairs); coavoid_vehicle_node_size %zu\n", N, predictor,
               planner, shared, conflicts, pairs, round8(vehicle) + shared + conflicts);
    }
    return 0;
}
C
cc -std=c11 "${pdefs[@]}" -I"$src/include" -I"$src/src/protocol" -I"$src/src/lcm" \
  -I"$src/src/auth" -I"$arm/lcmtypes/include" -I"$arm/lcmtypes/part-include" \
  "$work/vehicle.c" "${objs_host[@]}" -lccd -lm -o "$work/vehicle"
"$work/vehicle" "$host_planner" "$arm_planner" "$host_predictor" "$arm_predictor" \
  "$arm_vehicle" "$arm_inbox"
