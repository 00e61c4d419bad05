# The two set-up commands of the README:  make demo   and   make test
# Both install what is missing (Debian packages), configure and build.
PAPER_MODEL = models/3prru_paper.json
MODEL   ?= $(PAPER_MODEL)
# Each model builds in its own directory: build/ for the paper's, build-<file>
# for any other, so `make test MODEL=x.json` never mixes kernels.
BUILD   ?= $(if $(filter $(abspath $(MODEL)),$(abspath $(PAPER_MODEL))),build,build-$(basename $(notdir $(MODEL))))
RESULTS ?= results
PYTHON  ?= python3
DEB_PACKAGES = cmake gcc g++ clang libclang-rt-14-dev valgrind make python3 libgsl-dev \
               gnuplot-nox libmujoco-dev
FUZZ_SECONDS ?= 60
SUDO := $(shell [ "$$(id -u)" = 0 ] || echo sudo)

.PHONY: all deps build demo compare-designs test test-asan fuzz check-generated regenerate bench clean

all: build

deps:
	@missing=""; for p in $(DEB_PACKAGES); do \
	  dpkg-query -W -f='$${Status}' $$p 2>/dev/null | grep -q 'ok installed' || missing="$$missing $$p"; \
	done; \
	if [ -n "$$missing" ]; then \
	  echo "installing:$$missing"; \
	  $(SUDO) apt-get update -qq && \
	  DEBIAN_FRONTEND=noninteractive $(SUDO) apt-get install -y -qq --no-install-recommends $$missing; \
	fi

build: deps
	cmake -S . -B $(BUILD) -DCMAKE_BUILD_TYPE=Release -DPRRU_MODEL=$(abspath $(MODEL))
	cmake --build $(BUILD) -j 2

demo: build
	$(BUILD)/cli/prru paper --out $(RESULTS)
	$(MAKE) --no-print-directory compare-designs

# The paper's future work: three limbs (the paper's model) vs four
# (models/4prru.json), each in its own build directory.
compare-designs: deps
	$(MAKE) --no-print-directory build MODEL=$(PAPER_MODEL) BUILD=build
	$(MAKE) --no-print-directory build MODEL=models/4prru.json BUILD=build-4prru
	studies/compare_designs.sh build build-4prru $(RESULTS)/compare

test: build check-generated
	cd $(BUILD) && ctest --output-on-failure -j 2

# AddressSanitizer + UBSan build and ctest, fuzz corpus replay, valgrind on
# `prru paper` (own build directories; `make test` first for the Release one).
test-asan: build
	RELEASE_BUILD=$(abspath $(BUILD)) tests/sanitize.sh

# libFuzzer over the number, table, load-schedule and scenario parsers.
fuzz: deps
	FUZZ_SECONDS=$(FUZZ_SECONDS) fuzz/run.sh

# Fails when the committed generated/ (the paper model's kernels) is not
# what the generator makes now, whichever MODEL the build uses.
check-generated:
	@tmp=$$(mktemp -d) && \
	$(PYTHON) gen/prru_gen.py $(PAPER_MODEL) --out $$tmp --quiet && \
	if diff -r -q $$tmp generated >/dev/null; then echo "generated/ is up to date"; rm -rf $$tmp; \
	else diff -r -u generated $$tmp | head -40; rm -rf $$tmp; \
	  echo "generated/ is stale: run 'make regenerate' and commit"; exit 1; fi

regenerate:
	$(PYTHON) gen/prru_gen.py $(PAPER_MODEL) --out generated

bench: build
	$(BUILD)/bench/prru_bench

clean:
	rm -rf $(BUILD)
