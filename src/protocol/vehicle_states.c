/* SPDX-License-Identifier: MIT */
/*
 * The vehicle's two state machines (protocol.h): every transition either may make, as a
 * table. The vehicle (vehicle*.c) moves only through these tables; docs/protocol.md draws them from
 * here (tests/protocol_states.c prints the drawing, and the protocol_states test compares
 * it with the document).
 */
#include "protocol.h"

typedef struct {
    uint8_t from;
    uint8_t event;
    uint8_t to;
} transition_t;

#define P(x) COAVOID_VEHICLE_##x
#define E(x) COAVOID_VEHICLE_EVENT_##x

/* The phase. A cycle's start leaves any phase; the rest happen within a cycle. */
static const transition_t phase_table[] = {
    /* every cycle's start */
    {P(IDLE), E(FOLLOW), P(FOLLOWING)},
    {P(FOLLOWING), E(FOLLOW), P(FOLLOWING)},
    {P(FOLLOWED), E(FOLLOW), P(FOLLOWING)},
    {P(DECIDING), E(FOLLOW), P(FOLLOWING)},
    {P(GATHERING), E(FOLLOW), P(FOLLOWING)},
    {P(DECIDED), E(FOLLOW), P(FOLLOWING)},
    {P(ANSWERING), E(FOLLOW), P(FOLLOWING)},
    {P(ANSWER_GATHERING), E(FOLLOW), P(FOLLOWING)},
    {P(ANSWERED), E(FOLLOW), P(FOLLOWING)},
    {P(IDLE), E(DECIDE), P(DECIDING)},
    {P(FOLLOWING), E(DECIDE), P(DECIDING)},
    {P(FOLLOWED), E(DECIDE), P(DECIDING)},
    {P(DECIDING), E(DECIDE), P(DECIDING)},
    {P(GATHERING), E(DECIDE), P(DECIDING)},
    {P(DECIDED), E(DECIDE), P(DECIDING)},
    {P(ANSWERING), E(DECIDE), P(DECIDING)},
    {P(ANSWER_GATHERING), E(DECIDE), P(DECIDING)},
    {P(ANSWERED), E(DECIDE), P(DECIDING)},
    /* following: the intent goes out at once; the answer wait */
    {P(FOLLOWING), E(PUBLISH), P(FOLLOWING)},
    {P(FOLLOWING), E(ANSWER_WAIT), P(FOLLOWED)},
    {P(FOLLOWED), E(UNANSWERED), P(ANSWERING)},
    {P(FOLLOWED), E(STANDBY), P(DECIDED)},
    {P(FOLLOWED), E(SELF_COMMIT), P(DECIDED)},
    /* deciding for itself, from the cycle's start */
    {P(DECIDING), E(WAIT), P(DECIDING)},
    {P(DECIDING), E(GATHER), P(GATHERING)},
    {P(DECIDING), E(PUBLISH), P(DECIDED)},
    {P(GATHERING), E(WAIT), P(GATHERING)},
    {P(GATHERING), E(GATHER), P(GATHERING)},
    {P(GATHERING), E(PUBLISH), P(DECIDED)},
    {P(DECIDED), E(REDECIDE), P(DECIDING)},
    /* ... from the answer wait */
    {P(ANSWERING), E(WAIT), P(ANSWERING)},
    {P(ANSWERING), E(GATHER), P(ANSWER_GATHERING)},
    {P(ANSWERING), E(PUBLISH), P(ANSWERED)},
    {P(ANSWER_GATHERING), E(WAIT), P(ANSWER_GATHERING)},
    {P(ANSWER_GATHERING), E(GATHER), P(ANSWER_GATHERING)},
    {P(ANSWER_GATHERING), E(PUBLISH), P(ANSWERED)},
    {P(ANSWERED), E(REDECIDE), P(ANSWERING)},
    /* a self-commit due after the answer wait, whatever it decides meanwhile */
    {P(DECIDING), E(SELF_COMMIT), P(DECIDING)},
    {P(GATHERING), E(SELF_COMMIT), P(GATHERING)},
    {P(DECIDED), E(SELF_COMMIT), P(DECIDED)},
};

/* Its coordinator's plans. */
static const transition_t plan_table[] = {
    {P(PLAN_NONE), E(ACCEPT), P(PLAN_HOLDING)},
    {P(PLAN_HOLDING), E(ACCEPT), P(PLAN_HOLDING)},
    {P(PLAN_STANDBY), E(ACCEPT), P(PLAN_STANDBY)},
    {P(PLAN_ON_STANDBY), E(ACCEPT), P(PLAN_STANDBY)},
    {P(PLAN_SWITCHED), E(ACCEPT), P(PLAN_SWITCHED_HOLDING)},
    {P(PLAN_SWITCHED_HOLDING), E(ACCEPT), P(PLAN_SWITCHED_HOLDING)},
    {P(PLAN_HOLDING), E(STANDBY), P(PLAN_STANDBY)},
    {P(PLAN_HOLDING), E(COMMIT), P(PLAN_SWITCHED)},
    {P(PLAN_STANDBY), E(COMMIT), P(PLAN_SWITCHED)},
    {P(PLAN_SWITCHED_HOLDING), E(COMMIT), P(PLAN_SWITCHED)},
    {P(PLAN_HOLDING), E(ABORT), P(PLAN_NONE)},
    {P(PLAN_STANDBY), E(ABORT), P(PLAN_ON_STANDBY)},
    {P(PLAN_SWITCHED_HOLDING), E(ABORT), P(PLAN_SWITCHED)},
    {P(PLAN_NONE), E(CYCLE), P(PLAN_NONE)},
    {P(PLAN_HOLDING), E(CYCLE), P(PLAN_NONE)},
    {P(PLAN_STANDBY), E(CYCLE), P(PLAN_NONE)},
    {P(PLAN_ON_STANDBY), E(CYCLE), P(PLAN_NONE)},
    {P(PLAN_SWITCHED), E(CYCLE), P(PLAN_NONE)},
    {P(PLAN_SWITCHED_HOLDING), E(CYCLE), P(PLAN_NONE)},
};

#undef P
#undef E

/* The `to` of (from, event) in table, or `none`. O(table). */
static unsigned lookup(const transition_t *table, size_t n, unsigned from, unsigned event,
                       unsigned none)
{
    for (size_t i = 0; i < n; i++) {
        if (table[i].from == from && table[i].event == event) {
            return table[i].to;
        }
    }
    return none;
}

coavoid_vehicle_phase_t coavoid_vehicle_phase_next(coavoid_vehicle_phase_t from,
                                                   coavoid_vehicle_event_t event)
{
    return (coavoid_vehicle_phase_t)lookup(phase_table, sizeof phase_table / sizeof phase_table[0],
                                           (unsigned)from, (unsigned)event, COAVOID_VEHICLE_PHASES);
}

coavoid_vehicle_plan_t coavoid_vehicle_plan_next(coavoid_vehicle_plan_t from,
                                                 coavoid_vehicle_event_t event)
{
    return (coavoid_vehicle_plan_t)lookup(plan_table, sizeof plan_table / sizeof plan_table[0],
                                          (unsigned)from, (unsigned)event,
                                          COAVOID_VEHICLE_PLAN_STATES);
}

const char *coavoid_vehicle_phase_name(coavoid_vehicle_phase_t phase)
{
    static const char *const names[COAVOID_VEHICLE_PHASES] = {
        "IDLE",    "FOLLOWING", "FOLLOWED",         "DECIDING", "GATHERING",
        "DECIDED", "ANSWERING", "ANSWER_GATHERING", "ANSWERED"};
    return (unsigned)phase < COAVOID_VEHICLE_PHASES ? names[phase] : "?";
}

const char *coavoid_vehicle_plan_name(coavoid_vehicle_plan_t plan)
{
    static const char *const names[COAVOID_VEHICLE_PLAN_STATES] = {
        "NONE", "HOLDING", "STANDBY", "ON_STANDBY", "SWITCHED", "SWITCHED_HOLDING"};
    return (unsigned)plan < COAVOID_VEHICLE_PLAN_STATES ? names[plan] : "?";
}

const char *coavoid_vehicle_event_name(coavoid_vehicle_event_t event)
{
    static const char *const names[COAVOID_VEHICLE_EVENTS] = {
        "FOLLOW",     "DECIDE",  "WAIT",        "GATHER", "PUBLISH", "REDECIDE", "ANSWER_WAIT",
        "UNANSWERED", "STANDBY", "SELF_COMMIT", "ACCEPT", "COMMIT",  "ABORT",    "CYCLE"};
    return (unsigned)event < COAVOID_VEHICLE_EVENTS ? names[event] : "?";
}
