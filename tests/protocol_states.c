/* SPDX-License-Identifier: MIT */
/*
 * protocol_states.c: draws the vehicle's state machines from their tables
 * (src/protocol/vehicle_states.c, through coavoid_vehicle_phase_next and _plan_next) as
 * the block of docs/protocol.md between the markers below, so that the document cannot
 * drift from the code.
 *   protocol_states            prints the block
 *   protocol_states --check F  exit 0 when F holds exactly that block, 1 (saying so) if not
 *   protocol_states --write F  replaces the block in F
 */
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "protocol.h"

#define BEGIN                                                                                   \
    "<!-- vehicle-states: drawn by tests/protocol_states.c from src/protocol/vehicle_states.c " \
    "-->\n"
#define END "<!-- /vehicle-states -->\n"

typedef struct {
    char *text;
    size_t length;
    size_t capacity;
} buffer_t;

static void put(buffer_t *b, const char *s)
{
    const size_t n = strlen(s);
    if (b->length + n + 1u > b->capacity) {
        b->capacity = 2u * (b->length + n + 1u);
        b->text = realloc(b->text, b->capacity);
        if (b->text == NULL) {
            fprintf(stderr, "protocol_states: out of memory\n");
            exit(2);
        }
    }
    memcpy(b->text + b->length, s, n + 1u);
    b->length += n;
}

/* One machine: its transitions as a table and as a Mermaid diagram. An event that takes
 * every state to the same one is one row, from "any". `next` returns `states` for an
 * event not allowed. */
static void machine(buffer_t *b, const char *title, unsigned states, unsigned first_event,
                    unsigned last_event, unsigned (*next)(unsigned, unsigned),
                    const char *(*name)(unsigned))
{
    char line[256];
    snprintf(line, sizeof line, "#### %s\n\n| from | event | to |\n|---|---|---|\n", title);
    put(b, line);
    buffer_t diagram = {NULL, 0, 0};
    put(&diagram, "```mermaid\nstateDiagram-v2\n");
    for (unsigned e = first_event; e <= last_event; e++) {
        unsigned to = next(0u, e);
        unsigned from_any = to != states;
        for (unsigned s = 1; s < states && from_any; s++) {
            from_any = next(s, e) == to;
        }
        for (unsigned s = 0; s < states; s++) {
            unsigned t = next(s, e);
            if (t == states || (from_any && s > 0u)) {
                continue;
            }
            const char *from = from_any ? "any" : name(s);
            const char *ev = coavoid_vehicle_event_name((coavoid_vehicle_event_t)e);
            snprintf(line, sizeof line, "| %s | %s | %s |\n", from, ev, name(t));
            put(b, line);
            snprintf(line, sizeof line, "    %s --> %s: %s%s\n", from_any ? "[*]" : name(s),
                     name(t), ev, from_any ? " (from any)" : "");
            put(&diagram, line);
        }
    }
    put(&diagram, "```\n");
    put(b, "\n");
    put(b, diagram.text);
    free(diagram.text);
}

static unsigned phase_next(unsigned s, unsigned e)
{
    return (unsigned)coavoid_vehicle_phase_next((coavoid_vehicle_phase_t)s,
                                                (coavoid_vehicle_event_t)e);
}

static unsigned plan_next(unsigned s, unsigned e)
{
    return (unsigned)coavoid_vehicle_plan_next((coavoid_vehicle_plan_t)s,
                                               (coavoid_vehicle_event_t)e);
}

static const char *phase_name(unsigned s)
{
    return coavoid_vehicle_phase_name((coavoid_vehicle_phase_t)s);
}

static const char *plan_name(unsigned s)
{
    return coavoid_vehicle_plan_name((coavoid_vehicle_plan_t)s);
}

static void draw(buffer_t *b)
{
    put(b, BEGIN);
    machine(b, "The phase", COAVOID_VEHICLE_PHASES, COAVOID_VEHICLE_EVENT_FOLLOW,
            COAVOID_VEHICLE_EVENT_SELF_COMMIT, phase_next, phase_name);
    put(b, "\n");
    machine(b, "Its coordinator's plans of the cycle", COAVOID_VEHICLE_PLAN_STATES,
            COAVOID_VEHICLE_EVENT_ACCEPT, COAVOID_VEHICLE_EVENT_CYCLE, plan_next, plan_name);
    put(b, END);
}

static char *read_file(const char *path, size_t *length)
{
    FILE *f = fopen(path, "rb");
    if (f == NULL) {
        fprintf(stderr, "protocol_states: cannot open %s\n", path);
        exit(2);
    }
    buffer_t b = {NULL, 0, 0};
    char chunk[4096];
    size_t n;
    while ((n = fread(chunk, 1, sizeof chunk - 1u, f)) > 0) {
        chunk[n] = '\0';
        put(&b, chunk);
    }
    fclose(f);
    *length = b.length;
    return b.text;
}

/* --check or --write of the block in the document `path`; the exit status. */
static int check_or_write(const char *path, bool write, const buffer_t *block)
{
    size_t length = 0;
    char *doc = read_file(path, &length);
    char *begin = strstr(doc, BEGIN);
    char *end = begin != NULL ? strstr(begin, END) : NULL;
    int status = 0;
    if (end == NULL) {
        fprintf(stderr, "protocol_states: %s has no vehicle-states block\n", path);
        status = 1;
    } else if (!write) {
        end += strlen(END);
        const size_t old = (size_t)(end - begin);
        if (old != block->length || memcmp(begin, block->text, old) != 0) {
            fprintf(stderr,
                    "protocol_states: the state machines in %s are not those of "
                    "src/protocol/vehicle_states.c: run protocol_states --write %s\n",
                    path, path);
            status = 1;
        } else {
            printf("protocol_states: %s draws the tables as they are\n", path);
        }
    } else {
        end += strlen(END);
        FILE *f = fopen(path, "wb");
        if (f == NULL || fwrite(doc, 1, (size_t)(begin - doc), f) != (size_t)(begin - doc) ||
            fputs(block->text, f) < 0 || fputs(end, f) < 0 || fclose(f) != 0) {
            fprintf(stderr, "protocol_states: cannot write %s\n", path);
            status = 2;
        }
    }
    free(doc);
    return status;
}

int main(int argc, char **argv)
{
    buffer_t block = {NULL, 0, 0};
    draw(&block);
    int status = 0;
    if (argc == 1) {
        fputs(block.text, stdout);
    } else if (argc != 3 || (strcmp(argv[1], "--check") != 0 && strcmp(argv[1], "--write") != 0)) {
        fprintf(stderr, "usage: protocol_states [--check FILE | --write FILE]\n");
        status = 2;
    } else {
        status = check_or_write(argv[2], strcmp(argv[1], "--write") == 0, &block);
    }
    free(block.text);
    return status;
}
