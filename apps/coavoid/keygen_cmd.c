/* SPDX-License-Identifier: MIT */
/*
 * coavoid keygen: fresh Ed25519 key pairs for a scenario's fleet (auth.h): one secret key
 * file per node in DIR (coordinator.key, world.key, vehicle-ID.key; readable by the owner
 * only) and DIR/trust.txt, the trust file that lists every public key with its role.
 */
#define _POSIX_C_SOURCE 200809L

#include <errno.h>
#include <fcntl.h>
#include <stdio.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "auth.h"
#include "cli.h"
#include "commands.h"
#include "node.h"
#include "scenario.h"

#define KEYGEN_USAGE                                                                         \
    "usage: coavoid keygen SCENARIO.json --dir DIR\n"                                        \
    "\n"                                                                                     \
    "Writes a fresh key pair for every node of the scenario's fleet: DIR/coordinator.key,\n" \
    "DIR/world.key and DIR/vehicle-ID.key for each UAV (secret keys, mode 0600), and\n"      \
    "DIR/trust.txt, the trust file listing their public keys with their roles (key ids:\n"   \
    "the coordinator 1, the world 2, UAV ID 100 + ID). DIR is created (mode 0700) when it\n" \
    "does not exist; its parent must.\n"                                                     \
    "\n"                                                                                     \
    "exit status: 0 written, 2 invalid input or usage, 3 a file could not be written\n"

typedef struct {
    const char *scenario_path;
    const char *dir;
} keygen_options_t;

static void keygen_help(void)
{
    fputs(KEYGEN_USAGE, stdout);
}

static int keygen_option(int argc, char **argv, int *i, void *options)
{
    keygen_options_t *o = options;
    if (coavoid_cli_option_is(argv[*i], "--dir")) {
        return coavoid_cli_text_option(argc, argv, i, "--dir", "a directory", false, &o->dir);
    }
    return CLI_UNKNOWN_OPTION;
}

static const coavoid_cli_command_t keygen_command = {
    "keygen",    "coavoid keygen", 2,    {"SCENARIO.json", NULL}, "one scenario only",
    keygen_help, keygen_option,    false};

/* Writes text to DIR/name, created for its owner only. */
static int write_private(const char *dir, const char *name, const char *text)
{
    char path[4096];
    if (snprintf(path, sizeof path, "%s/%s", dir, name) >= (int)sizeof path) {
        return coavoid_cli_fail(CLI_EXIT_INVALID, "--dir: too long a path");
    }
    int fd = open(path, O_WRONLY | O_CREAT | O_TRUNC, 0600);
    size_t n = strlen(text);
    if (fd < 0 || fchmod(fd, 0600) != 0 || write(fd, text, n) != (ssize_t)n) {
        int e = errno;
        if (fd >= 0) {
            close(fd);
        }
        return coavoid_cli_fail(CLI_EXIT_INTERNAL, "%.200s: cannot write: %s", path, strerror(e));
    }
    return close(fd) == 0 ? CLI_CONTINUE
                          : coavoid_cli_fail(CLI_EXIT_INTERNAL, "%.200s: cannot write", path);
}

/* One node's key pair: its secret file, and its line appended to trust. */
static int one_key(const keygen_options_t *o, const char *file, uint32_t key_id,
                   coavoid_auth_role_t role, uint16_t node, char *trust, size_t trust_size)
{
    coavoid_auth_key_t key = {key_id, role, node, {0}};
    coavoid_auth_signer_t signer;
    memset(&signer, 0, sizeof signer);
    signer.key_id = key_id;
    char line[COAVOID_AUTH_LINE_MAX];
    if (coavoid_auth_keypair(key.public_key, signer.secret_key) != COA_OK ||
        coavoid_auth_signer_line(&signer, line, sizeof line) != COA_OK) {
        return coavoid_cli_fail(CLI_EXIT_INTERNAL, "internal error: no key pair (libsodium)");
    }
    int rc = write_private(o->dir, file, line);
    memset(line, 0, sizeof line);
    memset(&signer, 0, sizeof signer);
    if (rc == CLI_CONTINUE && coavoid_auth_key_line(&key, line, sizeof line) == COA_OK &&
        strlen(trust) + strlen(line) < trust_size) {
        strcat(trust, line);
    }
    return rc;
}

/* A new fleet key's line, appended to trust. */
static int fleet_line(char *trust, size_t trust_size)
{
    unsigned char key[COAVOID_AUTH_FLEET_KEY_BYTES];
    char line[COAVOID_AUTH_LINE_MAX];
    const bool ok = coavoid_auth_fleet_key(key) == COA_OK &&
                    coavoid_auth_fleet_line(key, line, sizeof line) == COA_OK &&
                    strlen(trust) + strlen(line) < trust_size;
    if (ok) {
        strcat(trust, line);
    }
    memset(key, 0, sizeof key);
    memset(line, 0, sizeof line);
    return ok ? CLI_CONTINUE
              : coavoid_cli_fail(CLI_EXIT_INTERNAL, "internal error: no fleet key (libsodium)");
}

/* DIR as it is, or created for its owner only once the scenario is known to be good
 * (a refused scenario leaves nothing behind). */
static int make_dir(const char *dir)
{
    if (mkdir(dir, 0700) == 0 || errno == EEXIST) {
        struct stat st;
        return stat(dir, &st) == 0 && S_ISDIR(st.st_mode)
                   ? CLI_CONTINUE
                   : coavoid_cli_fail(CLI_EXIT_INVALID, "--dir: '%.200s' is not a directory", dir);
    }
    return coavoid_cli_fail(CLI_EXIT_INVALID, "--dir: cannot create '%.200s': %s", dir,
                            strerror(errno));
}

static int keygen(void *options, coavoid_scenario_t *s)
{
    const keygen_options_t *o = options;
    int made = make_dir(o->dir);
    if (made != CLI_CONTINUE) {
        return made;
    }
    static char trust[COA_MAX_VEHICLES * COAVOID_AUTH_LINE_MAX + 3u * COAVOID_AUTH_LINE_MAX];
    char name[32];
    strcpy(trust, "# coavoid trust file: KEY_ID ROLE NODE_ID PUBLIC_KEY_HEX, and the fleet's\n"
                  "# secret key (fleet FLEET_KEY_HEX): keep this file as a secret key\n");
    int rc = fleet_line(trust, sizeof trust);
    if (rc == CLI_CONTINUE) {
        rc =
            one_key(o, "coordinator.key", COAVOID_AUTH_KEY_ID_COORDINATOR, COAVOID_AUTH_COORDINATOR,
                    (uint16_t)COAVOID_NODE_COORDINATOR_ID, trust, sizeof trust);
    }
    if (rc == CLI_CONTINUE) {
        rc = one_key(o, "world.key", COAVOID_AUTH_KEY_ID_WORLD, COAVOID_AUTH_WORLD,
                     (uint16_t)COAVOID_NODE_WORLD_ID, trust, sizeof trust);
    }
    for (size_t i = 0; i < s->vehicle_count && rc == CLI_CONTINUE; i++) {
        const uint16_t id = s->vehicles[i].id;
        snprintf(name, sizeof name, "vehicle-%u.key", (unsigned)id);
        rc = one_key(o, name, COAVOID_AUTH_KEY_ID_VEHICLE_BASE + id, COAVOID_AUTH_VEHICLE, id,
                     trust, sizeof trust);
    }
    if (rc == CLI_CONTINUE) {
        rc = write_private(o->dir, "trust.txt", trust);
    }
    return rc == CLI_CONTINUE ? CLI_EXIT_OK : rc;
}

int coavoid_command_keygen(int argc, char **argv)
{
    keygen_options_t o = {NULL, NULL};
    int status = coavoid_cli_parse_args(&keygen_command, argc, argv, &o, &o.scenario_path);
    if (status != CLI_CONTINUE) {
        return status;
    }
    if (o.dir == NULL) {
        return coavoid_cli_fail(CLI_EXIT_INVALID, "--dir: required (where the keys go)");
    }
    return coavoid_cli_run_scenario(o.scenario_path, keygen, &o);
}
