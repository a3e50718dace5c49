/* The records of ADCBI's DP3 (LAbuf) and DP2 (INTbuf) on the wire. As with
 * DP4's, every double travels as it is: an LLC that profiles (DP3) or plans
 * (DP2) a block again must get exactly the central run's samples. */
#include "ncpar/dist.h"
#include "seg_fields.h"

#include <stdio.h>
#include <string.h>

uint64_t ncp_dist_file_hash(const char *path, int64_t *size)
{
    FILE *f = fopen(path, "rb");
    uint64_t h = 14695981039346656037ULL;
    *size = -1;
    if (!f)
        return 0;
    int c;
    *size = 0;
    while ((c = getc(f)) != EOF) {
        h = (h ^ (uint64_t)(unsigned char)c) * 1099511628211ULL;
        ++*size;
    }
    if (ferror(f))
        *size = -1;
    fclose(f);
    return h;
}

void ncp_dist_seg_encode(const struct ncp_seg *s, ncp_seg_rec_t *r)
{
    memset(r, 0, sizeof *r);
    NCP_DIST_SEG_ENCODE(s, r);
}

void ncp_dist_seg_decode(const ncp_seg_rec_t *r, struct ncp_seg *s)
{
    memset(s, 0, sizeof *s);
    NCP_DIST_SEG_DECODE(r, s);
}

void ncp_dist_la_encode(const struct ncp_la *la, ncp_la_rec_t *r)
{
    ncp_dist_seg_encode(&la->s, &r->s);
    const double v[8] = { la->vmax,  la->acc,   la->acc_full, la->jerk,
                          la->a_eff, la->kappa, la->a_cap,    la->v_end };
    memcpy(r->la, v, sizeof v);
    const double box[7] = { la->box_kappa, la->box_a[0], la->box_a[1], la->box_a[2],
                            la->box_b[0],  la->box_b[1], la->box_b[2] };
    memcpy(r->box, box, sizeof box);
    r->flags = (int8_t)((la->blend ? NCP_LA_REC_T_FLAG_BLEND : 0) |
                        (la->after_stop ? NCP_LA_REC_T_FLAG_AFTER_STOP : 0));
}

void ncp_dist_la_decode(const ncp_la_rec_t *r, struct ncp_la *la)
{
    memset(la, 0, sizeof *la);
    ncp_dist_seg_decode(&r->s, &la->s);
    la->vmax = r->la[0];
    la->acc = r->la[1];
    la->acc_full = r->la[2];
    la->jerk = r->la[3];
    la->a_eff = r->la[4];
    la->kappa = r->la[5];
    la->a_cap = r->la[6];
    la->v_end = r->la[7];
    la->box_kappa = r->box[0];
    for (int j = 0; j < 3; j++) {
        la->box_a[j] = r->box[1 + j];
        la->box_b[j] = r->box[4 + j];
    }
    la->blend = (r->flags & NCP_LA_REC_T_FLAG_BLEND) != 0;
    la->after_stop = (r->flags & NCP_LA_REC_T_FLAG_AFTER_STOP) != 0;
}

void ncp_dist_op_encode(const struct ncp_dist_op *o, ncp_int_rec_t *r)
{
    ncp_dist_seg_encode(&o->s, &r->s);
    r->op = (int8_t)o->op;
    r->step = o->step;
}

void ncp_dist_op_decode(const ncp_int_rec_t *r, struct ncp_dist_op *o)
{
    memset(o, 0, sizeof *o);
    ncp_dist_seg_decode(&r->s, &o->s);
    o->op = (unsigned char)r->op;
    o->step = r->step;
}
