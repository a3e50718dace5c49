# src/auth: the shared key of the command channels and the MAC on every LCM
# message (ncpar/auth.h), on OpenSSL's libcrypto.
LIB_SRCS += $(wildcard src/auth/*.c)
