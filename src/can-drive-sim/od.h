/* Object dictionary of the simulated drive. */
#ifndef NCP_DRIVE_SIM_OD_H
#define NCP_DRIVE_SIM_OD_H

#include <stdint.h>

enum od_access { OD_RO, OD_RW };

struct od_entry {
    uint16_t index;
    uint8_t sub;
    uint8_t size; /* bytes */
    enum od_access access;
    uint32_t value;
};

struct od {
    struct od_entry e[64];
    int n;
};

void od_init(struct od *od);
/* NULL with *abort set when the object or sub-index does not exist. */
struct od_entry *od_find(struct od *od, uint16_t index, uint8_t sub, uint32_t *abort);
uint32_t od_get(struct od *od, uint16_t index, uint8_t sub);
void od_set(struct od *od, uint16_t index, uint8_t sub, uint32_t value);

#endif
