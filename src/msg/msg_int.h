/* src/msg's private constants and helpers: LCM's udpm wire format. */
#ifndef NCPAR_MSG_INT_H
#define NCPAR_MSG_INT_H

#include <stddef.h>
#include <stdint.h>

#define NCP_LC02_MAGIC 0x4c433032u /* "LC02": a whole message in one datagram */
#define NCP_LC03_MAGIC 0x4c433033u /* "LC03": one fragment of a larger one */
#define NCP_LC_SHORT_HEADER 8u     /* magic, seqno */
#define NCP_LC_LONG_HEADER 20u     /* magic, seqno, size, offset, fragment no, count */
#define NCP_LC_CHANNEL_MAX 63u     /* liblcm's LCM_MAX_CHANNEL_NAME_LENGTH */

/* 1 when buf is an LC03 fragment. */
int ncp_msg_is_fragment(const uint8_t *buf, size_t len);
/* The channel a first LC03 fragment names, NULL for any other datagram. */
const char *ncp_msg_fragment_channel(const uint8_t *buf, size_t len);

#endif
