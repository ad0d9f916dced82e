#!/bin/bash
# SPDX-License-Identifier: MIT
# Every kind of bad input to `coavoid plan` must exit 2 with exactly one line on stderr,
# starting "coavoid: " and naming the offending field or option, and print nothing on
# stdout. Bad scenarios are derived from one good scenario written below.
#
# usage: bash bad_inputs.sh <path-to-coavoid> <source-dir>   (VERBOSE=1 shows each message)
set -u
# shellcheck source=tests/cli/lib.bash
. "$(dirname "${BASH_SOURCE[0]}")/lib.bash" "$@"

cat >"$tmp/good.json" <<'JSON'
{
  "name": "bad-inputs base",
  "dt": 1.0,
  "horizon": 6,
  "beta": 5000,
  "vehicles": [
    {"id": 1, "priority": 1, "cruise_speed": 10, "climb_rate": 2, "steep_factor": 2,
     "radius": 5, "half_height": 3, "route": [[0, 0, 100], [100, 0, 100]],
     "initial_offset": 0, "max_offset": 20},
    {"id": 2, "priority": 2, "cruise_speed": 10, "climb_rate": 2,
     "radius": 5, "half_height": 3, "route": [[0, 500, 100], [100, 500, 100], [100, 600, 120]]},
    {"id": 3, "priority": 3, "cruise_speed": 12, "climb_rate": 3,
     "radius": 5, "half_height": 3, "route": [[0, 1000, 100], [100, 1000, 100]]}
  ],
  "obstacles": [
    {"type": "box", "min": [5000, 5000, 0], "max": [5100, 5100, 50]},
    {"type": "polytope", "vertices": [[6000, 0, 0], [6100, 0, 0], [6000, 100, 0], [6000, 0, 100]]}
  ],
  "tracks": [
    {"id": 7, "radius": 10, "half_height": 5, "position": [-3000, -3000, 500], "velocity": [1, 0, 0]},
    {"id": 8, "radius": 10, "half_height": 5, "path": [[0, -4000, 0, 300], [10, -4000, 100, 300]],
     "sigma": [5, 2]}
  ]
}
JSON

# mutate NAME PYTHON: writes $tmp/NAME.json from the good scenario after running the
# Python statements on it (as `s`). A string value "@RAW:text" is written as raw text,
# for literals Python's json cannot produce (1e999).
mutate() {
    python3 - "$tmp/good.json" "$2" "$tmp/$1.json" <<'PY'
import json, re, sys
s = json.load(open(sys.argv[1]))
exec(sys.argv[2])
text = json.dumps(s, indent=1)
text = re.sub(r'"@RAW:([^"]*)"', lambda m: m.group(1), text)
open(sys.argv[3], "w").write(text)
PY
}


# bad_scenario NAME FIELD PYTHON [REASON]: the scenario mutated by PYTHON is refused in
# both modes with a message "coavoid: FILE: FIELD: ..." (that also says REASON).
bad_scenario() {
    mutate "$1" "$3"
    also=${4:-}
    expect_bad "$1 (decoupled)" "$tmp/$1.json: $2: " plan "$tmp/$1.json" --mode decoupled
    expect_bad "$1 (centralised)" "$tmp/$1.json: $2: " plan "$tmp/$1.json" --mode centralised
    also=
}

# bad_scenario_under NAME FIELD PYTHON: as bad_scenario, but the message may name FIELD or
# a field inside it (a single-precision build refuses some numbers on their own, where a
# double build only refuses what they add up to).
bad_scenario_under() {
    mutate "$1" "$3"
    expect_bad "$1 (decoupled)" "$tmp/$1.json: $2" plan "$tmp/$1.json" --mode decoupled
    expect_bad "$1 (centralised)" "$tmp/$1.json: $2" plan "$tmp/$1.json" --mode centralised
}

# bad_scenario_double NAME FIELD PYTHON REASON: numbers that only a double build can read
# (beyond single precision, like 1e200) and whose combination overflows. Double: as
# bad_scenario, saying REASON. Single precision refuses a number on its own first, maybe
# in an earlier element, so there the message only has to name a field inside FIELD's
# parent (FIELD without its last [index]).
bad_scenario_double() {
    if [ "$single_precision" -eq 0 ]; then
        bad_scenario "$@"
    else
        bad_scenario_under "$1" "${2%\[*\]}" "$3"
    fi
}

# bad_text NAME FIELD TEXT: a scenario file with exactly this text is refused, naming FIELD.
bad_text() {
    printf '%s' "$3" >"$tmp/$1.json"
    expect_bad "$1" "$tmp/$1.json: $2" plan "$tmp/$1.json" --mode decoupled
}

# The base must be good, or every case below would pass for the wrong reason.
expect_ok "good scenario" plan "$tmp/good.json" --mode decoupled

# Which precision the core was built with: 1e39 is out of range only for float.
mutate precision_probe 's["obstacles"][0]["max"][0] = 1e39'
if "$bin" plan "$tmp/precision_probe.json" --mode decoupled >/dev/null 2>&1; then
    single_precision=0
else
    single_precision=1
fi

# ---- wrong types ----
bad_scenario type_name name 's["name"] = 5'
bad_scenario type_dt dt 's["dt"] = "1.0"'
bad_scenario type_dt_bool dt 's["dt"] = True'
bad_scenario type_horizon_string 'horizon' 's["horizon"] = "6"'
bad_scenario type_horizon_bool 'horizon' 's["horizon"] = True'
bad_scenario type_horizon_fraction 'horizon' 's["horizon"] = 1.5'
bad_scenario type_beta 'beta' 's["beta"] = "100"'
bad_scenario type_vehicles 'vehicles' 's["vehicles"] = {"id": 1}'
bad_scenario type_vehicle 'vehicles[1]' 's["vehicles"][1] = [1, 2]'
bad_scenario type_id_bool 'vehicles[0].id' 's["vehicles"][0]["id"] = True'
bad_scenario type_id_fraction 'vehicles[2].id' 's["vehicles"][2]["id"] = 2.5'
bad_scenario type_id_null 'vehicles[0].id' 's["vehicles"][0]["id"] = None'
bad_scenario type_priority 'vehicles[1].priority' 's["vehicles"][1]["priority"] = "1"'
bad_scenario type_cruise 'vehicles[0].cruise_speed' 's["vehicles"][0]["cruise_speed"] = [10]'
bad_scenario type_steep 'vehicles[0].steep_factor' 's["vehicles"][0]["steep_factor"] = 2.5'
bad_scenario type_route 'vehicles[0].route' 's["vehicles"][0]["route"] = "east"'
bad_scenario type_route_point 'vehicles[1].route[2]' 's["vehicles"][1]["route"][2] = {"x": 1}'
bad_scenario type_route_coordinate 'vehicles[1].route[1][2]' 's["vehicles"][1]["route"][1][2] = "100"'
bad_scenario short_route_point 'vehicles[0].route[1]' 's["vehicles"][0]["route"][1] = [1, 2]'
bad_scenario long_route_point 'vehicles[0].route[0]' 's["vehicles"][0]["route"][0] = [1, 2, 3, 4]'
bad_scenario type_initial_offset 'vehicles[0].initial_offset' 's["vehicles"][0]["initial_offset"] = 0.5'
bad_scenario type_max_offset 'vehicles[0].max_offset' 's["vehicles"][0]["max_offset"] = "20"'
bad_scenario type_obstacles 'obstacles' 's["obstacles"] = {"type": "box"}'
bad_scenario type_obstacle_type 'obstacles[0].type' 's["obstacles"][0]["type"] = 1'
bad_scenario type_box_min 'obstacles[0].min' 's["obstacles"][0]["min"] = 0'
bad_scenario type_tracks 'tracks' 's["tracks"] = 3'
bad_scenario type_track_id 'tracks[0].id' 's["tracks"][0]["id"] = "7"'
bad_scenario type_track_velocity 'tracks[0].velocity' 's["tracks"][0]["velocity"] = [1, 0]'
bad_scenario type_sigma 'tracks[1].sigma' 's["tracks"][1]["sigma"] = 5'
bad_text top_level_array '(top level): ' '[1, 2, 3]'
bad_text top_level_string '(top level): ' '"scenario"'

# ---- missing fields ----
for field in name dt horizon vehicles; do
    bad_scenario "missing_$field" "$field" "del s['$field']" missing
done
for field in id priority cruise_speed climb_rate radius half_height route; do
    bad_scenario "missing_vehicle_$field" "vehicles[1].$field" "del s['vehicles'][1]['$field']" missing
done
bad_scenario missing_obstacle_type 'obstacles[1].type' 'del s["obstacles"][1]["type"]'
bad_scenario missing_box_max 'obstacles[0].max' 'del s["obstacles"][0]["max"]'
bad_scenario missing_vertices 'obstacles[1].vertices' 'del s["obstacles"][1]["vertices"]'
bad_scenario missing_track_radius 'tracks[0].radius' 'del s["tracks"][0]["radius"]'
bad_scenario missing_track_velocity 'tracks[0].velocity' 'del s["tracks"][0]["velocity"]'
bad_scenario missing_track_position 'tracks[0].position' 'del s["tracks"][0]["position"]'

# ---- non-finite numbers (cJSON reads 1e999 as infinity) ----
bad_scenario inf_dt dt 's["dt"] = "@RAW:1e999"'
bad_scenario inf_horizon 'horizon' 's["horizon"] = "@RAW:1e999"'
bad_scenario inf_cruise 'vehicles[0].cruise_speed' 's["vehicles"][0]["cruise_speed"] = "@RAW:1e999"'
bad_scenario inf_coordinate 'vehicles[2].route[1][0]' 's["vehicles"][2]["route"][1][0] = "@RAW:-1e999"'
bad_scenario inf_box 'obstacles[0].max[2]' 's["obstacles"][0]["max"][2] = "@RAW:1e999"'
bad_scenario inf_vertex 'obstacles[1].vertices[3][1]' 's["obstacles"][1]["vertices"][3][1] = "@RAW:1e999"'
bad_scenario inf_track 'tracks[0].position[0]' 's["tracks"][0]["position"][0] = "@RAW:1e999"'
bad_scenario inf_track_path 'tracks[1].path[1][0]' 's["tracks"][1]["path"][1][0] = "@RAW:1e999"'

# ---- ranges ----
bad_scenario dt_zero dt 's["dt"] = 0'
bad_scenario dt_negative dt 's["dt"] = -0.5'
bad_scenario horizon_zero 'horizon' 's["horizon"] = 0'
bad_scenario horizon_too_long horizon 's["horizon"] = 10001' COA_MAX_HORIZON
bad_scenario beta_zero 'beta' 's["beta"] = 0'
bad_scenario beta_negative 'beta' 's["beta"] = -1'
bad_scenario beta_fraction 'beta' 's["beta"] = 1.5'
bad_scenario beta_huge 'beta' 's["beta"] = 4294967296'
bad_scenario floor_string 'min_altitude' 's["min_altitude"] = "50"' 'must be a number'
bad_scenario floor_bool 'min_altitude' 's["min_altitude"] = True' 'must be a number'
bad_scenario floor_null 'min_altitude' 's["min_altitude"] = None' 'must be a number'
bad_scenario floor_inf 'min_altitude' 's["min_altitude"] = "@RAW:1e999"' 'finite'
bad_scenario floor_high 'min_altitude' 's["min_altitude"] = 1.5e7' 'COAVOID_SCENARIO_MAX_ALTITUDE'
bad_scenario floor_low 'min_altitude' 's["min_altitude"] = -1e8' 'COAVOID_SCENARIO_MAX_ALTITUDE'
mutate floor_ok 's["min_altitude"] = -20.5'
expect_ok "min_altitude within its range" plan "$tmp/floor_ok.json" --mode decoupled
bad_scenario cruise_zero 'vehicles[0].cruise_speed' 's["vehicles"][0]["cruise_speed"] = 0'
bad_scenario cruise_negative 'vehicles[2].cruise_speed' 's["vehicles"][2]["cruise_speed"] = -10'
bad_scenario climb_zero 'vehicles[1].climb_rate' 's["vehicles"][1]["climb_rate"] = 0'
bad_scenario radius_zero 'vehicles[0].radius' 's["vehicles"][0]["radius"] = 0'
bad_scenario half_height_negative 'vehicles[0].half_height' 's["vehicles"][0]["half_height"] = -3'
bad_scenario id_zero 'vehicles[0].id' 's["vehicles"][0]["id"] = 0'
bad_scenario id_too_big 'vehicles[0].id' 's["vehicles"][0]["id"] = 65536'
bad_scenario priority_zero 'vehicles[0].priority' 's["vehicles"][0]["priority"] = 0'
bad_scenario steep_one 'vehicles[0].steep_factor' 's["vehicles"][0]["steep_factor"] = 1'
bad_scenario steep_too_big 'vehicles[0].steep_factor' 's["vehicles"][0]["steep_factor"] = 11' COA_MAX_STEEP_FACTOR
bad_scenario max_offset_negative 'vehicles[0].max_offset' 's["vehicles"][0]["max_offset"] = -1'
bad_scenario initial_beyond_max 'vehicles[0].initial_offset' 's["vehicles"][0]["initial_offset"] = -21'
bad_scenario initial_too_big 'vehicles[1].initial_offset' 's["vehicles"][1]["initial_offset"] = 40000'
bad_scenario no_vehicles 'vehicles' 's["vehicles"] = []'
bad_scenario too_many_vehicles vehicles \
    's["vehicles"] = [dict(s["vehicles"][0], id=i + 1, route=[[0, 100 * i, 100], [10, 100 * i, 100]]) for i in range(33)]' \
    COA_MAX_VEHICLES
bad_scenario duplicate_id 'vehicles[2].id' 's["vehicles"][2]["id"] = 1' duplicate
bad_scenario route_one_point 'vehicles[1].route' 's["vehicles"][1]["route"] = [[0, 0, 100]]'
bad_scenario route_empty 'vehicles[1].route' 's["vehicles"][1]["route"] = []'
bad_scenario route_vertical_leg 'vehicles[1].route[2]' 's["vehicles"][1]["route"][2] = [100, 500, 150]' 'no horizontal separation'
bad_scenario route_repeated_point 'vehicles[0].route[1]' 's["vehicles"][0]["route"][1] = [0, 0, 100]'
# Legs are measured as the core measures them, sqrt(dx*dx + dy*dy) in coa_real_t: distinct
# points can still be 0 apart (the squares underflow) or infinitely far apart (the squares
# or the differences overflow), and the message names the point and says which.
bad_scenario route_leg_underflow 'vehicles[0].route[1]' \
    's["vehicles"][0]["route"] = [[0, 0, 100], [1e-300, 0, 100]]' 'no horizontal separation'
bad_scenario route_leg_underflow_later 'vehicles[1].route[2]' \
    's["vehicles"][1]["route"] = [[0, 500, 100], [0, 0, 100], [1e-170, 0, 120]]' 'no horizontal separation'
bad_scenario_double route_leg_overflow 'vehicles[0].route[1]' \
    's["vehicles"][0]["route"] = [[0, 0, 100], [1e200, 0, 100]]' 'leg length is not finite'
bad_scenario_double route_leg_squares_overflow 'vehicles[2].route[1]' \
    's["vehicles"][2]["route"] = [[0, 0, 100], [1e154, 1e154, 100]]' 'leg length is not finite'
bad_scenario_double route_leg_difference_overflow 'vehicles[0].route[1]' \
    's["vehicles"][0]["route"] = [[-1e308, 0, 100], [1e308, 0, 100]]' 'leg length is not finite'
bad_scenario_double route_altitude_overflow 'vehicles[2].route[1]' \
    's["vehicles"][2]["route"] = [[0, 1000, -1e308], [100, 1000, 1e308]]' 'altitude change is not finite'
bad_scenario box_inverted 'obstacles[0].max' 's["obstacles"][0]["min"][1] = 5200' inverted
bad_scenario box_inverted_z 'obstacles[0].max' 's["obstacles"][0]["max"][2] = -1' inverted
bad_scenario polytope_three 'obstacles[1].vertices' 's["obstacles"][1]["vertices"].pop()' 'at least 4'
bad_scenario polytope_too_many 'obstacles[1].vertices' \
    's["obstacles"][1]["vertices"] = [[6000 + i % 7, i, (i * i) % 13] for i in range(257)]' \
    COA_POLYTOPE_MAX_VERTICES
bad_scenario obstacle_unknown_type 'obstacles[0].type' 's["obstacles"][0]["type"] = "sphere"'
bad_scenario obstacle_not_object 'obstacles[1]' 's["obstacles"][1] = "box"'
bad_scenario track_radius_zero 'tracks[1].radius' 's["tracks"][1]["radius"] = 0'
bad_scenario track_id_negative 'tracks[0].id' 's["tracks"][0]["id"] = -7'
bad_scenario track_path_descending 'tracks[1].path[1]' 's["tracks"][1]["path"][1][0] = -1'
bad_scenario track_path_empty 'tracks[1].path' 's["tracks"][1]["path"] = []'
bad_scenario track_path_short_point 'tracks[1].path[0]' 's["tracks"][1]["path"][0] = [0, 1, 2]'
bad_scenario track_both_kinds 'tracks[1].path' 's["tracks"][1]["position"] = [0, 0, 0]'
# A path leg's duration, displacement and velocity, in coa_real_t, must be finite.
bad_scenario_double track_path_time_overflow 'tracks[1].path[1]' \
    's["tracks"][1]["path"] = [[-1e308, -4000, 0, 300], [1e308, -4000, 100, 300]]' \
    'time since the previous point is not finite'
bad_scenario_double track_path_displacement_overflow 'tracks[1].path[1]' \
    's["tracks"][1]["path"] = [[0, -1e308, 0, 300], [10, 1e308, 0, 300]]' \
    'displacement from the previous point is not finite on the x axis'
bad_scenario_double track_path_velocity_overflow 'tracks[1].path[1]' \
    's["tracks"][1]["path"] = [[0, -4000, 0, 300], [1e-300, -4000, 1e10, 300]]' \
    'velocity from the previous point is not finite on the y axis'
bad_scenario_double track_path_velocity_overflow_later 'tracks[1].path[2]' \
    's["tracks"][1]["path"] = [[-10, -4000, 0, 300], [0, -4000, 0, 300], [5e-324, -4000, 0, 301]]' \
    'velocity from the previous point is not finite on the z axis'
bad_scenario sigma_negative 'tracks[1].sigma[1]' 's["tracks"][1]["sigma"][1] = -2'
bad_scenario sigma_short 'tracks[1].sigma' 's["tracks"][1]["sigma"] = [1]'

# ---- how much a scenario may carry (COAVOID_SCENARIO_MAX_* in src/scenario/scenario.h) ----
# limit NAME FIELD WHAT MAX CONSTANT PYTHON: PYTHON sets the array at FIELD to
# items(lambda i: ELEMENT). With MAX elements the scenario is accepted and planned
# (solved: what is added is far from the UAVs, and the horizon is 6 steps); with MAX + 1 it
# is refused in both modes with exactly the line "coavoid: FILE: FIELD: at most MAX WHATs
# are supported (CONSTANT), got MAX+1"; and so it is with MAX + 1 nulls, which no element
# check would pass: the count is checked before any element is read.
limit() {
    local name=$1 field=$2 what=$3 max=$4 constant=$5 build=$6 mode file want
    local items='items = lambda f: [None] * n if unread else [f(i) for i in range(n)]'
    mutate "${name}_at_limit" "n = $max; unread = False; $items; $build"
    for mode in decoupled centralised; do
        expect_ok "$name: $max accepted ($mode)" plan "$tmp/${name}_at_limit.json" --mode "$mode"
    done
    mutate "${name}_over" "n = $max + 1; unread = False; $items; $build"
    mutate "${name}_over_nulls" "n = $max + 1; unread = True; $items; $build"
    for file in "$tmp/${name}_over.json" "$tmp/${name}_over_nulls.json"; do
        want="coavoid: $file: $field: at most $max ${what}s are supported ($constant), got $((max + 1))"
        for mode in decoupled centralised; do
            expect_bad "$name: $((max + 1)) refused (${file##*/}, $mode)" "$want" \
                plan "$file" --mode "$mode"
            if [ "$(cat "$tmp/err")" != "$want" ]; then
                fail "$name: not exactly '$want': $(cat "$tmp/err")"
            fi
        done
    done
}
limit obstacles obstacles obstacle 256 COAVOID_SCENARIO_MAX_OBSTACLES \
    's["obstacles"] = items(lambda i: {"type": "box", "min": [5000 + 10 * i, 5000, 0], "max": [5005 + 10 * i, 5005, 50]} if i % 2 else {"type": "polytope", "vertices": [[-5000, 10 * i, 0], [-4990, 10 * i, 0], [-5000, 10 * i + 5, 0], [-5000, 10 * i, 10]]})'
limit tracks tracks track 64 COAVOID_SCENARIO_MAX_TRACKS \
    's["tracks"] = items(lambda i: dict(s["tracks"][i % 2], id=i))'
limit route_points 'vehicles[1].route' point 256 COAVOID_SCENARIO_MAX_ROUTE_POINTS \
    's["vehicles"][1]["route"] = items(lambda i: [i, 500, 100])'
limit track_points 'tracks[1].path' point 256 COAVOID_SCENARIO_MAX_TRACK_POINTS \
    's["tracks"][1]["path"] = items(lambda i: [i, -4000, i, 300])'

# ---- text-level problems ----
bad_text duplicate_key 'dt: ' '{"name": "x", "dt": 1, "dt": 2, "horizon": 3, "vehicles": []}'
bad_text invalid_json 'invalid JSON near line 1, column' '{"name": "x", "dt": 1,, "horizon": 3}'
bad_text truncated_json 'invalid JSON' '{"name": "x", "dt": 1, "horizon"'
bad_text trailing_garbage 'invalid JSON' '{"name": "x"} extra'
bad_text empty_file 'invalid JSON' ''
printf '{"name": "\xff\xfe", "dt": 1, "horizon": 3, "vehicles": []}' >"$tmp/bad_utf8.json"
expect_bad bad_utf8 "$tmp/bad_utf8.json: name: " plan "$tmp/bad_utf8.json" --mode decoupled
printf '{"name": "x"}\0' >"$tmp/nul.json"
expect_bad nul_byte "$tmp/nul.json: invalid JSON: NUL" plan "$tmp/nul.json" --mode decoupled
truncate -s 17M "$tmp/huge.json"
expect_bad too_large "$tmp/huge.json: larger than" plan "$tmp/huge.json" --mode decoupled
expect_bad missing_file "$tmp/absent.json: cannot open" plan "$tmp/absent.json" --mode decoupled
mkdir "$tmp/dir.json"
expect_bad directory "$tmp/dir.json: cannot read" plan "$tmp/dir.json" --mode decoupled
if [ "$(id -u)" -ne 0 ]; then
    cp "$tmp/good.json" "$tmp/unreadable.json"
    chmod 000 "$tmp/unreadable.json"
    expect_bad unreadable "$tmp/unreadable.json: cannot open" plan "$tmp/unreadable.json" --mode decoupled
fi

# ---- --priority ----
good=$tmp/good.json
expect_bad priority_missing_id '--priority: vehicle 3 is missing' plan "$good" --mode decoupled --priority 2,1
expect_bad priority_duplicate '--priority: 1 is listed twice' plan "$good" --mode decoupled --priority 1,1,2,3
expect_bad priority_unknown '--priority: 7 is not a vehicle id' plan "$good" --mode decoupled --priority 1,2,7
expect_bad priority_garbage '--priority' plan "$good" --mode decoupled --priority a,b,c
expect_bad priority_negative '--priority' plan "$good" --mode decoupled --priority 1,-2,3
expect_bad priority_empty '--priority' plan "$good" --mode decoupled --priority ''
expect_bad priority_empty_entry '--priority' plan "$good" --mode decoupled --priority 1,,2,3
expect_bad priority_trailing_comma '--priority' plan "$good" --mode decoupled --priority 1,2,3,
expect_bad priority_spaces '--priority' plan "$good" --mode decoupled --priority '1, 2, 3'
expect_bad priority_no_value '--priority' plan "$good" --mode decoupled --priority
expect_bad priority_centralised '--priority' plan "$good" --mode centralised --priority 1,2,3
expect_bad priority_twice '--priority' plan "$good" --mode decoupled --priority 1,2,3 --priority 3,2,1

# ---- --beta ----
for beta in 0 -1 1.5 abc '' 4294967296 ' 5' 5x +5; do
    expect_bad "beta '$beta'" '--beta' plan "$good" --mode decoupled --beta "$beta"
done
expect_bad beta_no_value '--beta' plan "$good" --mode decoupled --beta
expect_bad beta_equals '--beta' plan "$good" --mode decoupled --beta=0

# ---- --max-orders ----
for max in 0 -1 abc '' 1.5 4294967296 ' 5' 5x +5; do
    expect_bad "max-orders '$max'" '--max-orders: must be an integer' \
        plan "$good" --mode decoupled --reorder --max-orders "$max"
done
expect_bad max_orders_no_value '--max-orders: missing value' plan "$good" --mode decoupled --reorder --max-orders
expect_bad max_orders_equals '--max-orders' plan "$good" --mode decoupled --reorder --max-orders=0
expect_bad max_orders_twice '--max-orders: given more than once' \
    plan "$good" --mode decoupled --reorder --max-orders 2 --max-orders 3
expect_bad max_orders_without_reorder '--max-orders: only valid with --reorder' \
    plan "$good" --mode decoupled --max-orders 3
expect_bad max_orders_centralised '--max-orders: only valid with --reorder' \
    plan "$good" --mode centralised --max-orders 3

# ---- command line ----
expect_bad unknown_mode '--mode' plan "$good" --mode sideways
expect_bad empty_mode '--mode' plan "$good" --mode ''
expect_bad missing_mode '--mode' plan "$good"
expect_bad mode_no_value '--mode' plan "$good" --mode
expect_bad mode_twice '--mode' plan "$good" --mode decoupled --mode centralised
expect_bad reorder_centralised '--reorder' plan "$good" --mode centralised --reorder
expect_bad reorder_value '--reorder' plan "$good" --mode decoupled --reorder=yes
expect_bad unknown_option "'--fast'" plan "$good" --mode decoupled --fast
expect_bad missing_scenario 'SCENARIO' plan --mode decoupled
expect_bad extra_argument "'other.json'" plan "$good" other.json --mode decoupled
expect_bad unknown_command "'simulate'" simulate "$good"
expect_bad unknown_top_option "'--verbose'" --verbose
expect_bad no_command 'command'

# ---- limits that only the planner's sizes reveal ----
mutate eleven_vehicles 's["vehicles"] = [dict(s["vehicles"][0], id=i + 1, route=[[0, 100 * i, 100], [10, 100 * i, 100]]) for i in range(11)]'
expect_bad centralised_too_many 'COA_MAX_CENTRALISED' plan "$tmp/eleven_vehicles.json" --mode centralised

expect_bad beta_workspace_overflow '--beta 4294967295: too large' plan "$good" --mode decoupled --beta 4294967295
mutate scenario_beta_overflow 's["beta"] = 4294967295'
expect_bad scenario_beta_overflow "$tmp/scenario_beta_overflow.json: beta 4294967295: too large" \
    plan "$tmp/scenario_beta_overflow.json" --mode decoupled
# Each number is fine, their product is not.
bad_scenario_under step_product_overflow 'vehicles[1]' \
    's["vehicles"][1]["cruise_speed"] = 1e300; s["vehicles"][1]["climb_rate"] = 1e300'
# A reference that runs off to infinity within the horizon (one vehicle: beside the others
# its L*dh would be refused first, as too far from theirs to weigh exactly).
bad_scenario_double reference_not_finite 'vehicles[0]' \
    's["horizon"] = 1000; s["vehicles"] = [s["vehicles"][2]]; s["vehicles"][0]["cruise_speed"] = 1e306' \
    'reference position is not finite'
bad_scenario_under track_not_finite 'tracks[0]' \
    's["horizon"] = 1000; s["tracks"][0]["velocity"] = [1e306, 0, 0]'
# L*dh of 1e6 m^2 and of 0.1 * 0.1 m^2 (53 significant bits) cannot share exact 64-bit
# integer weights (the core's COA_ERR_RANGE): the vehicles are named, not the horizon.
bad_scenario weights_range 'vehicles[2]' \
    's["vehicles"][0].update(cruise_speed=1000, climb_rate=1000); s["vehicles"][2].update(cruise_speed=0.1, climb_rate=0.1)' \
    "and vehicles[0]'s"
# Steep factors 7..10 make the cost scale lcm(14, 16, 18, 20) = 5040, and over 10000 steps
# the worst-case cost passes 2^64; the core's costs are 128-bit, so this largest case
# passes the problem check (not refused as out of range: that message names the vehicles)
# and is then refused for memory: its cost-to-go tables (every offset within 32767 at
# each of 10000 steps) would take gigabytes, whatever beta the scenario gives.
mutate cost_range 's["horizon"] = 10000; s["vehicles"] = [dict(s["vehicles"][0], id=i + 1, steep_factor=7 + i, max_offset=32767, route=[[0, 100 * i, 100], [10, 100 * i, 100]]) for i in range(4)]'
expect_bad cost_range 'too large: the cost-to-go tables of a 10000-step horizon' \
    plan "$tmp/cost_range.json" --mode decoupled

# ---- help is not an error ----
for args in "--help" "-h" "plan --help" "plan -h"; do
    # shellcheck disable=SC2086
    "$bin" $args >"$tmp/out" 2>"$tmp/err"
    rc=$?
    if [ "$rc" -eq 0 ] && grep -q '^usage: coavoid' "$tmp/out" && [ ! -s "$tmp/err" ]; then
        pass
    else
        fail "coavoid $args: exit $rc, expected usage on stdout and exit 0"
    fi
done
if grep -q 'default 200000' <("$bin" plan --help); then pass; else fail "plan --help does not state the default beta"; fi
if grep -q -- '--max-orders N .*default 5040' <("$bin" plan --help); then pass; else fail "plan --help does not state the default --max-orders"; fi

# ---- --version: every program, every command, the number of include/coavoid/version.h ----
want=$(sed -n 's/^#define COAVOID_VERSION_\(MAJOR\|MINOR\|PATCH\) \([0-9]*\)$/\2/p' \
    "$src/include/coavoid/version.h" | paste -sd.)
check_version() { # NAME COMMAND...: prints "NAME VERSION (single|double precision)", exit 0
    local name=$1
    shift
    "$@" >"$tmp/out" 2>"$tmp/err"
    local rc=$?
    if [ "$rc" -eq 0 ] && [ ! -s "$tmp/err" ] &&
        grep -qx "$name $want ([a-z]* precision)" "$tmp/out" && [ "$(wc -l <"$tmp/out")" -eq 1 ]; then
        pass
    else
        fail "$* --version: exit $rc, '$(head -c 200 "$tmp/out")', expected '$name $want (... precision)'"
    fi
}
check_version coavoid "$bin" --version
for command in plan predict montecarlo "bench plan" "bench predict"; do
    # shellcheck disable=SC2086
    check_version coavoid "$bin" $command --version
done
drivers=$(dirname "$bin")
if [ -x "$drivers/coavoid-vehicle" ]; then
    for command in sim summary world keygen replay bridge "bench auth"; do
        # shellcheck disable=SC2086
        check_version coavoid "$bin" $command --version
    done
    check_version coavoid-vehicle "$drivers/coavoid-vehicle" --version
    check_version coavoid-coordinator "$drivers/coavoid-coordinator" --version
    # The drivers take the scenario as every command does, the first argument; --scenario
    # FILE, the old spelling, works with one warning line; both, or neither, is an error.
    paper=$src/scenarios/paper.json
    "$drivers/coavoid-vehicle" "$paper" --list-ids >"$tmp/ids-new" 2>"$tmp/ids-new.err"
    "$drivers/coavoid-vehicle" --scenario "$paper" --list-ids >"$tmp/ids-old" 2>"$tmp/ids-old.err"
    rc=$?
    if [ "$rc" -eq 0 ] && [ "$(cat "$tmp/ids-new")" = "$(printf '1\n2\n3')" ] && [ ! -s "$tmp/ids-new.err" ] &&
        cmp -s "$tmp/ids-new" "$tmp/ids-old" && [ "$(wc -l <"$tmp/ids-old.err")" -eq 1 ] &&
        grep -q '^coavoid: warning: --scenario FILE is deprecated .*first argument' "$tmp/ids-old.err"; then
        pass
    else
        fail "coavoid-vehicle --scenario (old spelling): exit $rc, $(head -c 300 "$tmp/ids-old.err")"
    fi
    for d in coavoid-vehicle coavoid-coordinator; do
        "$drivers/$d" "$paper" --scenario "$paper" --insecure >/dev/null 2>"$tmp/twice.err"
        rc=$?
        if [ "$rc" -eq 2 ] && grep -q 'the scenario is given twice' "$tmp/twice.err"; then pass; else
            fail "$d: scenario given twice: exit $rc, $(head -c 300 "$tmp/twice.err")"
        fi
        "$drivers/$d" --insecure >/dev/null 2>"$tmp/none.err"
        rc=$?
        if [ "$rc" -eq 2 ] && [ "$(wc -l <"$tmp/none.err")" -eq 1 ] && grep -q "missing SCENARIO.json (see '$d --help')" "$tmp/none.err"; then
            pass
        else
            fail "$d: no scenario: exit $rc, $(head -c 300 "$tmp/none.err")"
        fi
    done
fi

finish
