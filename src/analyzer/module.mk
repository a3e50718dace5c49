# sources of src/analyzer, appended by the module
LIB_SRCS += $(wildcard src/analyzer/*.c)
LIB_CXXSRCS += $(wildcard src/analyzer/*.cpp)
# `make lint` also checks the analyzer's layering: the calls between its files
# form no cycle (the run loop calls the handlers, the handlers the ground
# floor, nothing calls back up), and no file of src/ reaches another module's
# private header by a ../ path.
# (this fragment is read first: its rules must not become the default goal)
ifeq ($(.DEFAULT_GOAL),)
.DEFAULT_GOAL := all
endif
lint: lint-layers
lint-layers:
	$(Q)tests/tools/call-layers src/analyzer >/dev/null
	$(Q)! grep -rn '#include *"\.\./' src || { echo "src/: a private header of another module included by ../ path"; exit 1; }
.PHONY: lint-layers
