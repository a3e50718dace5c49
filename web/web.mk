# web/: the operator's panel (served by `cnc-run serve --http`). Its files are
# copied into $(BUILD)/web at `make` time, and three.js (npm, for the 3D
# preview) from $(BUILD)/npm where `make web-deps` put it: the page loads
# nothing from elsewhere. Without three.js the panel draws a 2D preview.
WEB_SRCS := $(wildcard web/*.html web/*.css web/*.js)
WEB_OUT  := $(WEB_SRCS:web/%=$(BUILD)/web/%)
NPM_DIR  := $(BUILD)/npm
THREE_DIR := $(NPM_DIR)/node_modules/three
THREE_JS := $(THREE_DIR)/build/three.module.js

all: $(WEB_OUT) $(BUILD)/web/vendor/.stamp

$(BUILD)/web/%: web/%
	@mkdir -p $(@D)
	$(Q)cp $< $@

# three.js and its orbit controls when installed, else neither (the stamp
# is remade when they appear or change)
$(BUILD)/web/vendor/.stamp: $(wildcard $(THREE_JS)) web/web.mk
	@mkdir -p $(@D)
	$(Q)if [ -f $(THREE_JS) ]; then cp $(THREE_JS) $(@D)/three.module.js && \
	    cp $(THREE_DIR)/examples/jsm/controls/OrbitControls.js $(@D)/; \
	    else rm -f $(@D)/three.module.js $(@D)/OrbitControls.js; fi
	$(Q)touch $@

# npm packages of the panel and its browser test (web/package.json, locked),
# installed into the build, never committed. Needs npm and its registry.
.PHONY: web-deps
web-deps:
	@mkdir -p $(NPM_DIR)
	cp web/package.json web/package-lock.json $(NPM_DIR)/
	cd $(NPM_DIR) && PUPPETEER_SKIP_DOWNLOAD=1 npm ci --no-audit --no-fund --loglevel=error
