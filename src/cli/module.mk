# the CLI is linked separately (not part of libncpar.a): see CLI_SRCS in the Makefile
