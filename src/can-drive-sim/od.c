#include <stddef.h>

#include "od.h"

static void add(struct od *od, uint16_t index, uint8_t sub, uint8_t size,
                enum od_access acc, uint32_t value)
{
    if (od->n < (int)(sizeof od->e / sizeof od->e[0]))
        od->e[od->n++] = (struct od_entry){index, sub, size, acc, value};
}

void od_init(struct od *od)
{
    od->n = 0;
    add(od, 0x1000, 0, 4, OD_RO, 0x00020192); /* CiA 402 servo drive */
    add(od, 0x1001, 0, 1, OD_RO, 0);          /* error register */
    add(od, 0x1006, 0, 4, OD_RW, 0);          /* communication cycle period, us */
    add(od, 0x1016, 0, 1, OD_RO, 1);          /* heartbeat consumer: one entry */
    add(od, 0x1016, 1, 4, OD_RW, 0);          /* ... node << 16 | time ms; 0 off */
    add(od, 0x1017, 0, 2, OD_RW, 100);        /* heartbeat producer, ms */
    add(od, 0x1400, 1, 4, OD_RW, 0x200);      /* RPDO1 COB-ID (+ node) */
    add(od, 0x1400, 2, 1, OD_RW, 1);          /* every SYNC */
    add(od, 0x1400, 5, 2, OD_RW, 0);          /* event timer: RPDO deadline, ms; 0 off */
    add(od, 0x1600, 0, 1, OD_RW, 2);
    add(od, 0x1600, 1, 4, OD_RW, 0x60400010);
    add(od, 0x1600, 2, 4, OD_RW, 0x607A0020);
    add(od, 0x1800, 1, 4, OD_RW, 0x180);
    add(od, 0x1800, 2, 1, OD_RW, 1);
    add(od, 0x1801, 1, 4, OD_RW, 0x280);      /* TPDO2 COB-ID (+ node) */
    add(od, 0x1801, 2, 1, OD_RW, 255);        /* event-driven until set to every SYNC */
    add(od, 0x1A01, 0, 1, OD_RW, 0);          /* TPDO2 unmapped until the master maps it */
    add(od, 0x1A01, 1, 4, OD_RW, 0);
    add(od, 0x1A00, 0, 1, OD_RW, 2);
    add(od, 0x1A00, 1, 4, OD_RW, 0x60410010);
    add(od, 0x1A00, 2, 4, OD_RW, 0x60640020);
    add(od, 0x603F, 0, 2, OD_RO, 0);          /* error code */
    add(od, 0x6040, 0, 2, OD_RW, 0);
    add(od, 0x6041, 0, 2, OD_RO, 0);
    add(od, 0x6007, 0, 2, OD_RW, 1);          /* abort connection option: fault */
    add(od, 0x605A, 0, 2, OD_RW, 2);          /* quick stop option: ramp, then disabled */
    add(od, 0x605E, 0, 2, OD_RW, 2);          /* fault reaction option: quick stop ramp */
    add(od, 0x6060, 0, 1, OD_RW, 0);
    add(od, 0x6061, 0, 1, OD_RO, 0);
    add(od, 0x6064, 0, 4, OD_RO, 0);
    add(od, 0x607A, 0, 4, OD_RW, 0);
    add(od, 0x6085, 0, 4, OD_RW, 2000000);    /* quick stop deceleration, counts/s^2 */
    add(od, 0x607C, 0, 4, OD_RW, 0);          /* home offset: the position at home */
    add(od, 0x6098, 0, 1, OD_RW, 35);         /* homing method (INTEGER8) */
    add(od, 0x6099, 0, 1, OD_RO, 2);          /* homing speeds, counts/s: */
    add(od, 0x6099, 1, 4, OD_RW, 20000);      /* ... searching the switch */
    add(od, 0x6099, 2, 4, OD_RW, 2000);       /* ... latching */
    add(od, 0x609A, 0, 4, OD_RW, 200000);     /* homing acceleration, counts/s^2 */
    add(od, 0x60FD, 0, 4, OD_RO, 0);          /* digital inputs: bit 2 home switch */
    add(od, 0x60C2, 1, 1, OD_RW, 1);          /* interpolation period value */
    add(od, 0x60C2, 2, 1, OD_RW, 0xFD);       /* ... index: 10^-3 s */
}

struct od_entry *od_find(struct od *od, uint16_t index, uint8_t sub, uint32_t *abort)
{
    int index_seen = 0;
    for (int i = 0; i < od->n; i++) {
        if (od->e[i].index != index)
            continue;
        index_seen = 1;
        if (od->e[i].sub == sub)
            return &od->e[i];
    }
    *abort = index_seen ? 0x06090011u : 0x06020000u;
    return NULL;
}

uint32_t od_get(struct od *od, uint16_t index, uint8_t sub)
{
    uint32_t abort;
    const struct od_entry *e = od_find(od, index, sub, &abort);
    return e ? e->value : 0;
}

void od_set(struct od *od, uint16_t index, uint8_t sub, uint32_t value)
{
    uint32_t abort;
    struct od_entry *e = od_find(od, index, sub, &abort);
    if (e)
        e->value = value;
}
