# `make install` / `make uninstall` (PREFIX, DESTDIR) and `make deb`.
# Layout: the binaries in PREFIX/bin; the panel, the sample programs and the
# example machine INIs in PREFIX/share/ncpar (where an installed cnc-run looks,
# relative to itself: src/cli/datadir.c); the manual pages; the systemd unit,
# its generator and the udev rule; the example machine in SYSCONFDIR/ncpar
# (never over one that is there). UNITDIR and UDEVDIR: /lib/... for
# PREFIX=/usr, as Debian 12 places them.
PREFIX     ?= /usr/local
DESTDIR    ?=
BINDIR      = $(PREFIX)/bin
DATADIR     = $(PREFIX)/share/ncpar
MANDIR      = $(PREFIX)/share/man
SYSCONFDIR ?= $(if $(filter /usr,$(PREFIX)),/etc,$(PREFIX)/etc)
LIBROOT     = $(if $(filter /usr,$(PREFIX)),,$(PREFIX))/lib
UNITDIR    ?= $(LIBROOT)/systemd/system
GENDIR     ?= $(LIBROOT)/systemd/system-generators
UDEVDIR    ?= $(LIBROOT)/udev/rules.d
INSTALL    ?= install

INSTALL_BINS = $(BUILD)/cnc-run $(BUILD)/cnc-ctl $(BUILD)/cnc-axis $(BUILD)/cnc-drive-sim
INSTALL_WEB  = $(filter-out %/.stamp,$(WEB_OUT) $(wildcard $(BUILD)/web/vendor/*.js))
INSTALL_SUBST = sed -e 's|@BINDIR@|$(BINDIR)|g' -e 's|@SYSCONFDIR@|$(SYSCONFDIR)|g'

.PHONY: install uninstall deb
install: all
	$(INSTALL) -d $(DESTDIR)$(BINDIR) $(DESTDIR)$(DATADIR)/web \
	    $(DESTDIR)$(DATADIR)/ncprograms $(DESTDIR)$(DATADIR)/rt-config/paper4 \
	    $(DESTDIR)$(MANDIR)/man1 $(DESTDIR)$(MANDIR)/man5 $(DESTDIR)$(UNITDIR) \
	    $(DESTDIR)$(GENDIR) $(DESTDIR)$(UDEVDIR) $(DESTDIR)$(SYSCONFDIR)/ncpar
	$(INSTALL) -m 0755 $(INSTALL_BINS) $(DESTDIR)$(BINDIR)/
	$(INSTALL) -m 0644 $(filter-out $(BUILD)/web/vendor/%,$(INSTALL_WEB)) $(DESTDIR)$(DATADIR)/web/
	$(if $(filter $(BUILD)/web/vendor/%,$(INSTALL_WEB)),$(INSTALL) -d $(DESTDIR)$(DATADIR)/web/vendor && \
	    $(INSTALL) -m 0644 $(filter $(BUILD)/web/vendor/%,$(INSTALL_WEB)) $(DESTDIR)$(DATADIR)/web/vendor/)
	$(INSTALL) -m 0644 ncprograms/*.ngc $(DESTDIR)$(DATADIR)/ncprograms/
	$(INSTALL) -m 0644 rt-config/*.ini rt-config/*.tbl $(DESTDIR)$(DATADIR)/rt-config/
	$(INSTALL) -m 0644 rt-config/paper4/* $(DESTDIR)$(DATADIR)/rt-config/paper4/
	$(INSTALL) -m 0644 $(filter %.1,$(MAN_OUT)) $(DESTDIR)$(MANDIR)/man1/
	$(INSTALL) -m 0644 $(filter %.5,$(MAN_OUT)) $(DESTDIR)$(MANDIR)/man5/
	$(INSTALL_SUBST) deploy/systemd/ncpar@.service.in >$(DESTDIR)$(UNITDIR)/ncpar@.service
	chmod 0644 $(DESTDIR)$(UNITDIR)/ncpar@.service
	$(INSTALL_SUBST) deploy/systemd/ncpar-affinity.in >$(DESTDIR)$(GENDIR)/ncpar-affinity
	chmod 0755 $(DESTDIR)$(GENDIR)/ncpar-affinity
	$(INSTALL) -m 0644 deploy/udev/60-ncpar.rules $(DESTDIR)$(UDEVDIR)/
	test -e $(DESTDIR)$(SYSCONFDIR)/ncpar/sim-3axis.ini || \
	    $(INSTALL) -m 0644 rt-config/sim-3axis.ini $(DESTDIR)$(SYSCONFDIR)/ncpar/

# What install placed, and nothing else: the machine INIs and the key in
# SYSCONFDIR/ncpar are the integrator's and stay.
uninstall:
	rm -f $(addprefix $(DESTDIR)$(BINDIR)/,cnc-run cnc-ctl cnc-axis cnc-drive-sim)
	rm -rf $(DESTDIR)$(DATADIR)
	rm -f $(addprefix $(DESTDIR)$(MANDIR)/man1/,cnc-run.1 cnc-ctl.1 cnc-axis.1 cnc-drive-sim.1)
	rm -f $(DESTDIR)$(MANDIR)/man5/ncpar.ini.5
	rm -f $(DESTDIR)$(UNITDIR)/ncpar@.service $(DESTDIR)$(GENDIR)/ncpar-affinity
	rm -f $(DESTDIR)$(UDEVDIR)/60-ncpar.rules

# The Debian package (debian/), into the folder above this one as
# dpkg-buildpackage puts it.
deb:
	dpkg-buildpackage -b -us -uc
