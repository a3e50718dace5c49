/* The fields of a segment that ACCDECbuf (ncp_accdec_rec_t) and the segment
 * record of LAbuf and INTbuf (ncp_seg_rec_t) both carry, under the same
 * names: one copy of the mapping for both wire types (module-internal). */
#ifndef NCP_DIST_SEG_FIELDS_H
#define NCP_DIST_SEG_FIELDS_H

#include <string.h>

/* r: a record with kind, term, traverse, angular, sync, line, aux, start,
 * end, seg[10], geom[15]; s: a const struct ncp_seg * */
#define NCP_DIST_SEG_ENCODE(s, r)                                                              \
    do {                                                                                       \
        (r)->kind = (int8_t)(s)->kind;                                                         \
        (r)->term = (int8_t)(s)->term;                                                         \
        (r)->traverse = (int8_t)(s)->traverse;                                                 \
        (r)->angular = (int8_t)(s)->angular;                                                   \
        (r)->sync = (int8_t)(s)->sync;                                                         \
        (r)->line = (int32_t)(s)->line;                                                        \
        (r)->aux = (int32_t)(s)->aux;                                                          \
        memcpy((r)->start, (s)->start, sizeof (r)->start);                                     \
        memcpy((r)->end, (s)->end, sizeof (r)->end);                                           \
        const double seg_[10] = { (s)->length, (s)->feed,   (s)->blend_feed, (s)->tolerance,   \
                                  (s)->merge_tol, (s)->dwell, (s)->tool_z, (s)->pitch,         \
                                  (s)->rev_rpm, (s)->r0 };                                     \
        memcpy((r)->seg, seg_, sizeof seg_);                                                   \
        memcpy((r)->geom, (s)->center, sizeof (s)->center);                                    \
        memcpy((r)->geom + 3, (s)->normal, sizeof (s)->normal);                                \
        memcpy((r)->geom + 6, (s)->u, sizeof (s)->u);                                          \
        memcpy((r)->geom + 9, (s)->w, sizeof (s)->w);                                          \
        (r)->geom[12] = (s)->r1;                                                               \
        (r)->geom[13] = (s)->angle;                                                            \
        (r)->geom[14] = (s)->axial;                                                            \
    } while (0)

/* the other way: s, a struct ncp_seg *, already zeroed */
#define NCP_DIST_SEG_DECODE(r, s)                                                              \
    do {                                                                                       \
        (s)->kind = (uint8_t)(r)->kind;                                                        \
        (s)->term = (uint8_t)(r)->term;                                                        \
        (s)->traverse = (uint8_t)(r)->traverse;                                                \
        (s)->angular = (uint8_t)(r)->angular;                                                  \
        (s)->sync = (uint8_t)(r)->sync;                                                        \
        (s)->line = (uint32_t)(r)->line;                                                       \
        (s)->aux = (uint32_t)(r)->aux;                                                         \
        memcpy((s)->start, (r)->start, sizeof (s)->start);                                     \
        memcpy((s)->end, (r)->end, sizeof (s)->end);                                           \
        (s)->length = (r)->seg[0];                                                             \
        (s)->feed = (r)->seg[1];                                                               \
        (s)->blend_feed = (r)->seg[2];                                                         \
        (s)->tolerance = (r)->seg[3];                                                          \
        (s)->merge_tol = (r)->seg[4];                                                          \
        (s)->dwell = (r)->seg[5];                                                              \
        (s)->tool_z = (r)->seg[6];                                                             \
        (s)->pitch = (r)->seg[7];                                                              \
        (s)->rev_rpm = (r)->seg[8];                                                            \
        (s)->r0 = (r)->seg[9];                                                                 \
        memcpy((s)->center, (r)->geom, sizeof (s)->center);                                    \
        memcpy((s)->normal, (r)->geom + 3, sizeof (s)->normal);                                \
        memcpy((s)->u, (r)->geom + 6, sizeof (s)->u);                                          \
        memcpy((s)->w, (r)->geom + 9, sizeof (s)->w);                                          \
        (s)->r1 = (r)->geom[12];                                                               \
        (s)->angle = (r)->geom[13];                                                            \
        (s)->axial = (r)->geom[14];                                                            \
    } while (0)

#endif
