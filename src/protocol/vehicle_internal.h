/* SPDX-License-Identifier: MIT */
/*
 * vehicle_internal.h: the vehicle node's state and the functions its files share
 * (vehicle.c, vehicle_decide.c, vehicle_order.c, vehicle_agreement.c). Each function's
 * contract is at its definition. Not part of the API: protocol.h is.
 */
#ifndef COAVOID_VEHICLE_INTERNAL_H
#define COAVOID_VEHICLE_INTERNAL_H

#include "protocol_internal.h"

/* Decided cycles without a conflict of its own after which a raised rank returns to 0
 * (docs/protocol.md, "Priority negotiation"). */
#define RANK_HOLD_CYCLES 3u
/* Decisions again within one cycle after being overtaken (poll), at most: each follows a
 * raise, and each UAV raises at most RAISES_MAX times an episode, so a cascade through a
 * cluster ends anyway; the bound keeps a cycle's work bounded whatever peers announce. */
#define REDECISIONS_MAX 4u
/* Raises of its rank per episode (raise_rank), at most: the first above every UAV before
 * it, the others only as far as they must. Over 100 encounters (seed 1, no loss, raises
 * counting only the members of its cluster), 1, 2 and 3 left 8, 6 and 5 of the 60
 * four-UAV encounters some order solves with a loss of separation; with 5 UAVs 3 and 5
 * left 12 and 11 of 29. More turns help little, and each reorders the cluster again. */
#define RAISES_MAX 3u
/* The order search (search_order): clusters of at most ORDER_MEMBERS_MAX UAVs, and at
 * most ORDER_TRIES_MAX priority orders a search (5!, every order of 5 UAVs). Past that a
 * search could take n! orders of n single-UAV searches each: the greedy raise remains. */
#define ORDER_MEMBERS_MAX 8u
#define ORDER_TRIES_MAX 120u
/* How a UAV enters the view of a cycle's start (snapshot): not at all, by its intent of
 * the cycle before, or, in its first cycle, by its first intent with the offset it starts
 * at held (what it flew before it planned anything). */
#define SNAPSHOT_NONE 0u
#define SNAPSHOT_PREVIOUS 1u
#define SNAPSHOT_FIRST 2u

struct coavoid_vehicle_node {
    coavoid_vehicle_node_config_t config;
    coavoid_vehicle_node_state_t state;
    coa_real_t dh;
    int64_t first_cycle_start;
    int64_t cycle_start;
    int64_t wait_deadline;
    /* Following: when a conflict of its own with no answer yet makes it plan for itself
     * within the cycle (answer_overdue, the phase's ANSWER_WAIT). */
    int64_t answer_deadline;
    /* When answer_overdue found the held plan's self-commit not yet due: when it is
     * (INT64_MAX: none), and for which plan. */
    int64_t self_commit_at;
    int64_t self_commit_plan;
    bool self_answered; /* it answered its own conflict in the cycle before (distrust) */
    bool was_coordinated;
    bool cycle_conflict;    /* a conflict of its own in this cycle's prediction */
    bool distrust;          /* not following a coordinator it hears (cycle()) */
    int64_t distrust_cycle; /* the cycle it began */
    int64_t distrust_utime; /* and when */
    bool fault;             /* an internal error in this cycle */
    int64_t intent_sequence;
    int64_t status_sequence;
    int64_t last_plan_utime;
    /* The plan_id of the coordinator's plan of this cycle it switched to (state.plan).
     * Plans are ordered within a cycle only (node.h, step 4). */
    int64_t cycle_plan_id;
    bool cycle_plan_failed;  /* one listed it, in time, but was not solved */
    bool cycle_plan_refused; /* one listed it and was refused (on_plan) */
    bool last_cycle_refused; /* the same, of the cycle before (its heartbeat comes first) */
    bool unanswered;         /* had a conflict of its own in the last cycle and no plan came */
    /* Priority negotiation (docs/protocol.md): how many times it raised its rank
     * (state.rank) in this episode, and for how many decided cycles in a row it has had
     * no conflict. */
    uint32_t raises;
    uint32_t calm_cycles;
    int64_t settled_cycle; /* the cycle whose conflict settle_rank counted */
    /* The UAVs before it when it last decided in this cycle, with the sequence of the
     * intent it had of each, and how many times it decided again in redecided_cycle. */
    size_t decided_count;
    uint16_t decided_id[COAVOID_NODE_MAX_PEERS];
    int64_t decided_sequence[COAVOID_NODE_MAX_PEERS];
    uint32_t decided_digest[COAVOID_NODE_MAX_PEERS]; /* intent_digest of what it decided on */
    uint32_t decided_news; /* the inbox's world_news when it last decided */
    int64_t decided_cycle; /* the cycle it last decided in (note_order) */
    int64_t news_cycle;    /* the last cycle it decided again on world news (reconsider) */
    int64_t redecided_cycle;
    uint32_t redecisions;
    /* The other UAVs' rows in this cycle's solved plans (the latest plan_id each): what
     * each is to fly from this cycle's start, which a plan for this UAV is checked
     * against instead of their intents (record_rows). */
    size_t row_count;
    uint16_t row_id[COAVOID_NODE_MAX_PEERS];
    int64_t row_plan_id[COAVOID_NODE_MAX_PEERS];
    uint32_t row_samples[COAVOID_NODE_MAX_PEERS];
    int32_t row_offsets[COAVOID_NODE_MAX_PEERS][COAVOID_NODE_MAX_SAMPLES];

    /* The coordinator's plan it accepted this cycle and flies once it is committed
     * (docs/protocol.md; state.plan holds it): its row, and the plan's UAVs, whose
     * SWITCHED is a commit too. */
    int64_t pending_plan_id;
    uint32_t pending_count;
    int32_t pending_offsets[COAVOID_NODE_MAX_SAMPLES];
    size_t pending_members;
    uint16_t pending_ids[COA_MAX_VEHICLES];
    bool pending_accepted[COA_MAX_VEHICLES]; /* an ACCEPT heard from that UAV (own: sent) */
    int64_t pending_since;                   /* when it accepted */
    /* Copies still to send, and when the next goes: its intent, its SWITCHED. */
    uint32_t intent_copies_left;
    int64_t intent_copy_at;
    uint32_t answer_copies_left; /* of its last answer: ACCEPT or SWITCHED */
    int64_t answer_copy_at;
    int8_t answer_kind;
    int64_t answer_plan_id;
    coavoid_agreement_t tx_agreement;

    /* The adopted plan: offsets of samples plan_start .. plan_start + plan_count - 1; past
     * its end the last offset holds. */
    int64_t plan_start;
    uint32_t plan_count;
    int32_t plan_offsets[COAVOID_NODE_MAX_SAMPLES];

    /* This cycle's intent: samples k .. k + N. */
    coa_vec3_t own_reference[COAVOID_NODE_MAX_SAMPLES];
    int32_t own_offsets[COAVOID_NODE_MAX_SAMPLES];
    coa_vec3_t own_samples[COAVOID_NODE_MAX_SAMPLES];

    int32_t plan_out[COAVOID_NODE_MAX_SAMPLES];
    int32_t checked[COAVOID_NODE_MAX_SAMPLES];       /* a coordinator's plan over this window */
    coa_intent_plan_t plans[COAVOID_NODE_MAX_PEERS]; /* itself first, then the live peers */
    coa_intent_plan_t tall[COAVOID_NODE_MAX_PEERS];  /* the same, with unbounded height */
    uint32_t labels[COAVOID_NODE_MAX_PEERS];
    bool include[COAVOID_NODE_MAX_PEERS];
    coavoid_intent_t tx_intent;
    coavoid_status_t tx_status;

    /* The order search of this cycle (search_order): what it started the cycle as, the
     * group's members (indices into the view of the cycle's start) and their problem, and
     * the ranks it agreed for each member (agreed_cycle: the cycle they hold for, until
     * each member's own intent of the cycle says its rank). */
    coavoid_intent_t order_own; /* itself as its peers have it when the cycle began */
    int32_t start_offsets[COAVOID_NODE_MAX_SAMPLES]; /* its plan when the cycle began */
    uint8_t order_own_kind;                          /* SNAPSHOT_* */
    uint8_t order_kind[COAVOID_NODE_MAX_PEERS];
    size_t order_member[ORDER_MEMBERS_MAX];
    coa_vehicle_t order_vehicles[ORDER_MEMBERS_MAX];
    coa_vec3_t order_reference[ORDER_MEMBERS_MAX][COAVOID_NODE_MAX_PROBLEM_SAMPLES];
    const coa_vec3_t *order_references[ORDER_MEMBERS_MAX];
    int32_t order_offsets[ORDER_MEMBERS_MAX * COAVOID_NODE_MAX_SAMPLES];
    int32_t ahead_offsets[ORDER_MEMBERS_MAX * COAVOID_NODE_MAX_PROBLEM_SAMPLES]; /* look_ahead */
    int64_t agreed_cycle;
    size_t searched_first; /* first intents of the cycle its last search saw (first_intents) */
    size_t agreed_count;
    uint16_t agreed_id[ORDER_MEMBERS_MAX];
    int32_t agreed_rank[ORDER_MEMBERS_MAX];
    /* The joint plan's last search that found none (search_joint): its cycle and its
     * problem's digest. */
    int64_t joint_failed_cycle;
    uint64_t joint_failed_digest;

    coavoid_node_solver_t solver;
    coavoid_node_inbox_t inbox;
    coavoid_node_view_t view;
    coavoid_node_problem_tracks_t problem_tracks;
};

/* vehicle.c */
void coavoid_vehicle_adopt(coavoid_vehicle_node_t *node, const int32_t *offsets, uint32_t count);
bool coavoid_vehicle_answering(const coavoid_vehicle_node_t *node);
void coavoid_vehicle_build_own(coavoid_vehicle_node_t *node, int64_t k);
int coavoid_vehicle_finish(coavoid_vehicle_node_t *node, int64_t now);
uint32_t coavoid_vehicle_first_copies(const coavoid_vehicle_node_t *node);
bool coavoid_vehicle_flies_plan(const coavoid_vehicle_node_t *node);
bool coavoid_vehicle_holds_plan(const coavoid_vehicle_node_t *node);
coavoid_lcm_intent_info_t coavoid_vehicle_intent_info(const coavoid_vehicle_node_t *node,
                                                      int64_t now, int64_t sequence);
coa_vec3_t coavoid_vehicle_lifted(coa_vec3_t reference, int32_t offset, coa_real_t dh);
bool coavoid_vehicle_on_standby(const coavoid_vehicle_node_t *node);
void coavoid_vehicle_phase_on(coavoid_vehicle_node_t *node, coavoid_vehicle_event_t event);
void coavoid_vehicle_plan_on(coavoid_vehicle_node_t *node, coavoid_vehicle_event_t event);
int coavoid_vehicle_publish_intent(coavoid_vehicle_node_t *node, int64_t now);
bool coavoid_vehicle_started(const coavoid_vehicle_node_t *node);

/* vehicle_decide.c */
int coavoid_vehicle_decide(coavoid_vehicle_node_t *node, int64_t now);
int coavoid_vehicle_decide_own(coavoid_vehicle_node_t *node, int64_t now);
void coavoid_vehicle_drop_rank(coavoid_vehicle_node_t *node);
size_t coavoid_vehicle_gather(coavoid_vehicle_node_t *node, int64_t now);
int64_t coavoid_vehicle_gather_end(const coavoid_vehicle_node_t *node);
int coavoid_vehicle_missed_conflict(coavoid_vehicle_node_t *node, int64_t now, bool *conflict);
coa_problem_t coavoid_vehicle_own_problem(const coavoid_vehicle_node_t *node,
                                          coa_vehicle_t *vehicle, const coa_vec3_t **references);
int coavoid_vehicle_predict(coavoid_vehicle_node_t *node, size_t n, coa_predict_result_t *result);
int coavoid_vehicle_reconsider(coavoid_vehicle_node_t *node, int64_t now);
int coavoid_vehicle_search_self(coavoid_vehicle_node_t *node, int64_t now,
                                coa_plan_result_t *result);

/* vehicle_order.c */
bool coavoid_vehicle_first_intent(const coavoid_vehicle_node_t *node,
                                  const coavoid_node_peer_t *peer);
size_t coavoid_vehicle_first_intents(const coavoid_vehicle_node_t *node);
int coavoid_vehicle_search_order(coavoid_vehicle_node_t *node);
bool coavoid_vehicle_searches(const coavoid_vehicle_node_t *node);
void coavoid_vehicle_snapshot_own(coavoid_vehicle_node_t *node);

/* vehicle_agreement.c */
bool coavoid_vehicle_all_accepted(const coavoid_vehicle_node_t *node);
int coavoid_vehicle_answer(coavoid_vehicle_node_t *node, int64_t now, int8_t kind, int64_t plan_id);
int coavoid_vehicle_answer_overdue(coavoid_vehicle_node_t *node, int64_t now);
void coavoid_vehicle_distrust_from(coavoid_vehicle_node_t *node, int64_t k, int64_t now);
int coavoid_vehicle_on_agreement(void *owner, const coavoid_agreement_t *msg);
void coavoid_vehicle_on_plan(void *owner, const coavoid_plan_t *msg,
                             const coavoid_lcm_plan_info_t *info, const coa_plan_result_t *result,
                             const int32_t *offsets);
bool coavoid_vehicle_on_plan_row(void *owner, const coavoid_plan_t *msg);
int coavoid_vehicle_plan_hits_known(coavoid_vehicle_node_t *node, const int32_t *offsets,
                                    size_t count, int64_t now, bool own);
bool coavoid_vehicle_row_flown(const coavoid_vehicle_node_t *node, uint16_t id,
                               const int32_t *offsets, size_t count);
int coavoid_vehicle_self_commit(coavoid_vehicle_node_t *node, int64_t now);

#endif /* COAVOID_VEHICLE_INTERNAL_H */
