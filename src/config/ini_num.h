/* Numbers in the machine INI (ini_num.c), shared by its readers (config.c,
 * config_home.c, config_io.c, config_kins.c). */
#ifndef NCPAR_CONFIG_INI_NUM_H
#define NCPAR_CONFIG_INI_NUM_H

/* 1 if v is a plain decimal number (sign, digits, point, exponent, trailing
 * blanks): hex, inf, nan or a trailing unit are not what a machinist reading
 * the file would take them for. */
int ncp_ini_decimal(const char *v);
/* A plain decimal from lo to hi into *out: 0, or -1 (out untouched). */
int ncp_ini_number(const char *v, double lo, double hi, double *out);

#endif
