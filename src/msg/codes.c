/* The status's modal codes as a machinist writes them ("G91.1", "M8"): one
 * spelling for cnc-ctl's lines, the JSON and so the browser panel. */
#include "ncpar/msg.h"

#include <stdio.h>

int ncp_msg_code_name(char letter, int code10, char *buf, size_t size)
{
    if (code10 < 0 || size == 0)
        return -1;
    int n = code10 % 10 ? snprintf(buf, size, "%c%d.%d", letter, code10 / 10, code10 % 10)
                        : snprintf(buf, size, "%c%d", letter, code10 / 10);
    return n < 0 || (size_t)n >= size ? -1 : n;
}

int ncp_msg_active_codes_text(const ncp_status_t *s, char *buf, size_t size)
{
    size_t len = 0;
    if (size == 0)
        return -1;
    buf[0] = 0;
    for (int i = 0; i < 13 + 4; i++) {
        int m = i >= 13;
        char name[16];
        if (ncp_msg_code_name(m ? 'M' : 'G', m ? s->mcodes[i - 13] * 10 : s->gcodes[i], name,
                              sizeof name) < 0)
            continue;
        int n = snprintf(buf + len, size - len, "%s%s", len ? " " : "", name);
        if (n < 0 || (size_t)n >= size - len)
            return -1;
        len += (size_t)n;
        if (!m && s->gcodes[i] == 640 && (s->g64_p > 0 || s->g64_q > 0)) {
            n = snprintf(buf + len, size - len, " P%g Q%g", s->g64_p, s->g64_q);
            if (n < 0 || (size_t)n >= size - len)
                return -1;
            len += (size_t)n;
        }
    }
    return (int)len;
}
