# snag: the quick start on a fresh Debian 12 machine (as root):
#   make demo   installs what is missing, builds, checks the bundled sample sequence
#   make test   installs what is missing, builds, runs every test
BUILD ?= build
JOBS ?= $(shell nproc)
SNAG := $(BUILD)/cli/snag
DEMO_SEQUENCE := samples/drape
DEMO_REPORT := $(BUILD)/demo-report

# Everything the build and the tests need, as Debian 12 packages.
DEBIAN_PACKAGES := cmake g++ make libcgal-dev libassimp-dev libeigen3-dev libcli11-dev \
  nlohmann-json3-dev libfast-float-dev libgtest-dev libgmock-dev googletest \
  libmpfr-dev libgmp-dev libtinyobjloader-dev
# apt-get needs root; use sudo when make runs as another user.
SUDO := $(shell [ "$$(id -u)" = 0 ] || echo sudo)

.PHONY: all deps build demo test clean

all: build

# Installs only the packages that are missing, and touches apt only when one is.
deps:
	@missing=""; \
	for p in $(DEBIAN_PACKAGES); do \
	  dpkg-query -W -f='$${Status}\n' $$p 2>/dev/null | grep -q '^install ok installed$$' \
	    || missing="$$missing $$p"; \
	done; \
	if [ -n "$$missing" ]; then \
	  echo "make deps: installing$$missing"; \
	  $(SUDO) apt-get update && \
	  DEBIAN_FRONTEND=noninteractive $(SUDO) apt-get install -y $$missing; \
	else \
	  echo "make deps: every Debian package is installed"; \
	fi

build: deps
	cmake -S . -B $(BUILD) -DCMAKE_BUILD_TYPE=Release
	cmake --build $(BUILD) -j$(JOBS)

# snag exits 1 when it finds crossings, and this sample is made to have them: only a status
# above 1 (usage, input or internal error) fails the demo.
demo: build
	@echo
	@echo "== $(SNAG) check $(DEMO_SEQUENCE) --out $(DEMO_REPORT)"
	@status=0; $(SNAG) check $(DEMO_SEQUENCE) --out $(DEMO_REPORT) || status=$$?; \
	if [ $$status -gt 1 ]; then echo "snag failed with exit status $$status"; exit $$status; fi; \
	echo; \
	echo "exit status $$status (1: intersections found, as this sample is made to show)"; \
	echo "reports in $(DEMO_REPORT)/; the first pairs:"; \
	head -n 6 $(DEMO_REPORT)/pairs.csv

test: build
	cd $(BUILD) && ctest --output-on-failure -j$(JOBS)

clean:
	rm -rf $(BUILD)
