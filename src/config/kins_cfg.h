/* [KINS] and [JOINT_n] of the machine INI (config_kins.c), read by config.c's
 * loader. Not part of the public contract. */
#ifndef NCPAR_CONFIG_KINS_CFG_H
#define NCPAR_CONFIG_KINS_CFG_H

#include "ncpar/config.h"

#include <stddef.h>

/* What the file said, before COORDINATES (which may come later) tells
 * which axis joint n drives. */
struct kins_load {
    struct ncp_joint_cfg raw[NCP_AXES];   /* by joint number */
    unsigned set[NCP_AXES];               /* JK_* bits given */
    unsigned line[NCP_AXES];              /* of [JOINT_n], 0 = not in the file */
    unsigned offset_line[3];              /* X/Y/Z_OFFSET, 0 = not given */
    unsigned kins_line;                   /* KINEMATICS, 0 = not given (trivkins) */
};

/* [JOINT_0] .. [JOINT_8] -> 0 .. 8, else -1 */
int ncp_kins_joint_section(const char *sec);
/* One key of [KINS] or [JOINT_n]: 1 taken, 0 unknown key, -1 bad value (why
 * says more), -2 not one of its sections. */
int ncp_kins_cfg_key(struct kins_load *kl, struct ncp_machine_cfg *c, const char *sec,
                     const char *k, const char *v, unsigned line, char *why, size_t len);
/* After the whole file: the joints' limits by axis (coords: COORDINATES as
 * given, letters in joint order), and the checks across keys. 0, or -1 with
 * msg and *line (the line at fault). */
int ncp_kins_cfg_finish(struct kins_load *kl, struct ncp_machine_cfg *c, const char *coords,
                        char *msg, size_t len, unsigned *line);

#endif
