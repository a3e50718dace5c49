# src/http: the operator's panel (HTTP and WebSocket) on libwebsockets. Where
# its headers are missing the build goes on without it (stub.c) and
# `serve --http` says so; `make HTTP_LWS=0` builds that way on purpose.
HTTP_LWS ?= $(shell test -r /usr/include/libwebsockets.h && echo 1 || echo 0)
ifeq ($(HTTP_LWS),1)
LIB_SRCS += src/http/server.c src/http/gate.c src/http/jobs.c src/http/query.c \
            src/http/files.c src/http/upload.c
# cnc-run is static: libwebsockets' own dependencies are named
HTTP_LDLIBS = -lwebsockets -lssl -lcrypto -lz -lcap
else
LIB_SRCS += src/http/stub.c
endif
LIB_SRCS += src/http/upname.c src/http/policy.c src/http/request.c src/http/flatjson.c src/http/listen.c
