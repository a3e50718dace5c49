/* The simulated machine behind the backend interface. */
#include "ncpar/backend.h"

#include <stdlib.h>
#include <string.h>

/* The plant and, for injected timing, its recent periods. */
struct sim_be {
    struct ncp_sim s;
    struct ncp_sim_timed t;
};

static int sim_start(struct ncp_backend *b, double pos[NCP_AXES])
{
    struct ncp_sim *s = &((struct sim_be *)b->impl)->s;
    for (int j = 0; j < NCP_AXES; j++)
        pos[j] = s->ax[j].x;
    return 0;
}

static int sim_cycle(struct ncp_backend *b, const double cmd[NCP_AXES], const double next[NCP_AXES],
                     double act[NCP_AXES])
{
    struct sim_be *sb = b->impl;
    if (b->timing)
        ncp_sim_step_timed(&sb->s, &sb->t, b->timing, cmd, next, act);
    else
        ncp_sim_step(&sb->s, cmd, next, act);
    return 0;
}

static void sim_stop(struct ncp_backend *b)
{
    (void)b;
}

static void sim_describe(const struct ncp_backend *b, char *buf, size_t len)
{
    (void)b;
    if (len)
        buf[0] = 0;
}

static void sim_close(struct ncp_backend *b)
{
    free(b->impl);
    b->impl = NULL;
}

static void sim_enable(struct ncp_backend *b, int on)
{
    struct ncp_sim *s = &((struct sim_be *)b->impl)->s;
    s->disabled = !on;
}

static const struct ncp_backend_ops sim_ops = {
    "sim", sim_start, sim_cycle, sim_stop, sim_describe, sim_close, sim_enable, NULL, NULL, NULL, NULL,
    NULL, NULL,
};

int ncp_backend_open_sim(struct ncp_backend *b, const struct ncp_machine_cfg *cfg,
                         struct ncp_diag *d)
{
    struct sim_be *sb = calloc(1, sizeof *sb);
    if (!sb)
        return ncp_diag_set(d, NCP_ERR_IO, 0, 0, "out of memory for the simulated machine");
    ncp_sim_init(&sb->s, cfg, cfg->sim_start);
    memset(b, 0, sizeof *b);
    b->ops = &sim_ops;
    b->impl = sb;
    return NCP_OK;
}
