# cnc-ctl: the operator's client of a serving NCK. Linked dynamically with
# liblcm (it has no static archive); of libncpar.a it takes only the generated
# message types and src/msg's pure helpers.
CTL_SRCS = $(wildcard src/ctl/*.c)
CTL_OBJS = $(CTL_SRCS:%.c=$(BUILD)/%.o)

all: $(BUILD)/cnc-ctl

# (the library by its path: $(LIB) is defined after the fragments are read)
$(BUILD)/cnc-ctl: $(CTL_OBJS) $(BUILD)/libncpar.a
	$(Q)$(CC) $(ALL_CFLAGS) $(LDFLAGS) -o $@ $(CTL_OBJS) $(BUILD)/libncpar.a -llcm $(LDLIBS)
