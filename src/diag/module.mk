LIB_SRCS += src/diag/diag.c
