/* Numbers in the machine INI (ini_num.h): the ground floor of its readers
 * (config.c and the section parsers config_home.c, config_io.c,
 * config_kins.c), which call it and which it calls none of. */
#include "ini_num.h"
#include "ncpar/num.h"

#include <string.h>

int ncp_ini_decimal(const char *v)
{
    const char *p = v;
    if (*p == '+' || *p == '-')
        p++;
    size_t digits = strspn(p, "0123456789");
    p += digits;
    if (*p == '.') {
        size_t frac = strspn(p + 1, "0123456789");
        digits += frac;
        p += 1 + frac;
    }
    if (!digits)
        return 0;
    if (*p == 'e' || *p == 'E') {
        p++;
        if (*p == '+' || *p == '-')
            p++;
        size_t e = strspn(p, "0123456789");
        if (!e)
            return 0;
        p += e;
    }
    p += strspn(p, " \t");
    return *p == '\0';
}

int ncp_ini_number(const char *v, double lo, double hi, double *out)
{
    if (!ncp_ini_decimal(v))
        return -1;
    return ncp_num_double(v, lo, hi, out);
}
