/* Number formatting for canonical text: exact printf equivalents without the
 * cost of printf's format parsing and locale machinery. Internal to the
 * executor; ncp_fmt_fixed4 is public in executor.h. */
#ifndef NCPAR_EXECUTOR_FMT_NUM_H
#define NCPAR_EXECUTOR_FMT_NUM_H

#include <stddef.h>
#include <stdint.h>
#include "ncpar/executor.h"

/* Longest "%.4f" / "%f" text of any double: 309 integer digits, sign, point,
 * decimals, NUL, rounded up. */
#define NCP_FMT_NUM_MAX NCP_FMT_FIXED4_MAX

/* "%d": writes into buf (>= 12 bytes), returns length. */
size_t ncp_fmt_int(char *buf, int32_t v);

/* "%f" (6 decimals), for the rare calls rs274 prints that way. buf holds
 * NCP_FMT_NUM_MAX bytes. */
size_t ncp_fmt_fixed6(char *buf, double v);

#endif
