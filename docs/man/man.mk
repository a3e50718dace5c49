# Manual pages into $(BUILD)/man: cnc-run(1), cnc-ctl(1), cnc-axis(1) and
# cnc-drive-sim(1) as written here, with the version and date filled in, and
# ncpar.ini(5) printed by tools/ini-man from the table the INI reader checks
# keys against; ini-man probes the reader first and a disagreement stops the
# build. The date is SOURCE_DATE_EPOCH's when set (a reproducible package).
MAN1_SRCS := $(wildcard docs/man/*.1)
MAN_OUT   := $(MAN1_SRCS:docs/man/%=$(BUILD)/man/%) $(BUILD)/man/ncpar.ini.5
MAN_DATE  := $(shell date -u -d @$${SOURCE_DATE_EPOCH:-$$(date +%s)} +%Y-%m-%d)
INI_MAN   := $(BUILD)/tools/ini-man

all: $(MAN_OUT)

$(BUILD)/man/%.1: docs/man/%.1 $(VERSION_H)
	@mkdir -p $(@D)
	$(Q)sed -e "s/@VERSION@/$$(tools/version)/" -e "s/@DATE@/$(MAN_DATE)/" $< >$@

$(INI_MAN): tools/ini-man.c $(LIB) | $(GEN_STAMP)
	@mkdir -p $(@D)
	@$(if $(Q),echo "  CC   $<")
	$(Q)$(CC) $(CPPFLAGS) $(ALL_CFLAGS) -o $@ $< $(LIB) $(LDLIBS) -lstdc++

$(BUILD)/man/ncpar.ini.5: $(INI_MAN) $(VERSION_H)
	@mkdir -p $(@D)
	$(Q)$(INI_MAN) "$$(tools/version)" "$(MAN_DATE)" >$@.tmp && mv $@.tmp $@ || { rm -f $@.tmp; exit 1; }
