/* The simulated machine behind the backend interface. */
#include "ncpar/backend.h"

#include <stdlib.h>
#include <string.h>

static int sim_start(struct ncp_backend *b, double pos[NCP_AXES])
{
    struct ncp_sim *s = b->impl;
    for (int j = 0; j < NCP_AXES; j++)
        pos[j] = s->ax[j].x;
    return 0;
}

static int sim_cycle(struct ncp_backend *b, const double cmd[NCP_AXES], const double next[NCP_AXES],
                     double act[NCP_AXES])
{
    ncp_sim_step(b->impl, cmd, next, act);
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
    struct ncp_sim *s = b->impl;
    s->disabled = !on;
}

static const struct ncp_backend_ops sim_ops = {
    "sim", sim_start, sim_cycle, sim_stop, sim_describe, sim_close, sim_enable, NULL,
};

int ncp_backend_open_sim(struct ncp_backend *b, const struct ncp_machine_cfg *cfg,
                         struct ncp_diag *d)
{
    static const double origin[NCP_AXES];
    struct ncp_sim *s = malloc(sizeof *s);
    if (!s)
        return ncp_diag_set(d, NCP_ERR_IO, 0, 0, "out of memory for the simulated machine");
    ncp_sim_init(s, cfg, origin);
    memset(b, 0, sizeof *b);
    b->ops = &sim_ops;
    b->impl = s;
    return NCP_OK;
}
