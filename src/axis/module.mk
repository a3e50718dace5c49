# cnc-axis: one low-level axis controller (LLC) of the distributed NCK (seed
# 002). Its own binary, not in the library: the library's lcm backend is the
# other end. Linked statically like cnc-run, with the C++ runtime the
# library's kinematics bring.
AXIS_SRCS = $(wildcard src/axis/*.c)
AXIS_OBJS = $(AXIS_SRCS:%.c=$(BUILD)/%.o)

all: $(BUILD)/cnc-axis

$(BUILD)/cnc-axis: $(AXIS_OBJS) $(BUILD)/libncpar.a
	$(Q)$(CXX) $(ALL_CXXFLAGS) $(CLI_LDFLAGS) -o $@ $(AXIS_OBJS) $(BUILD)/libncpar.a $(LDLIBS)
