# The README's two commands: `make demo` and `make test`. Both install the Debian packages they
# need first (scripts/install-deps.sh, only what is missing).
BUILD ?= build
SANITIZE_BUILD ?= build-sanitize
FUZZ_BUILD ?= build-fuzz
FUZZ_SECONDS ?= 300
JOBS ?= 2

.PHONY: all deps build test test-sanitize fuzz fuzz-build demo bench format clean

all: build

deps:
	@bash scripts/install-deps.sh

# The Python package is built with Debian's interpreter (python3-numpy, python3-torch), not a
# pyenv python3 earlier on PATH.
PYTHON ?= /usr/bin/python3

build: deps
	cmake -S . -B $(BUILD) -DCMAKE_BUILD_TYPE=Release -DDIFFPILLS_PYTHON=ON -DPython3_EXECUTABLE=$(PYTHON)
	cmake --build $(BUILD) -j$(JOBS)

# Every test, then the whole suite once more under AddressSanitizer + UndefinedBehaviorSanitizer,
# then each fuzzer for 30 seconds.
test: build
	ctest --test-dir $(BUILD) --output-on-failure
	$(MAKE) test-sanitize
	$(MAKE) fuzz FUZZ_SECONDS=30

test-sanitize: deps
	cmake -S . -B $(SANITIZE_BUILD) -DCMAKE_BUILD_TYPE=RelWithDebInfo -DDIFFPILLS_SANITIZE=ON \
	  -DDIFFPILLS_BUILD_BENCHMARKS=OFF
	cmake --build $(SANITIZE_BUILD) -j$(JOBS)
	ASAN_OPTIONS=detect_leaks=1 UBSAN_OPTIONS=print_stacktrace=1 \
	  ctest --test-dir $(SANITIZE_BUILD) --output-on-failure -LE no_sanitize

# The libFuzzer targets (fuzz/), built with clang-14 under ASan + UBSan, each run for FUZZ_SECONDS
# from the committed seed corpus (fuzz/corpus/); new inputs collect in $(FUZZ_BUILD)/corpus and a
# failing input is saved in $(FUZZ_BUILD)/artifacts.
fuzz-build: deps
	cmake -S . -B $(FUZZ_BUILD) -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_CXX_COMPILER=clang++-14 \
	  -DDIFFPILLS_FUZZ=ON -DDIFFPILLS_BUILD_TESTS=OFF -DDIFFPILLS_BUILD_BENCHMARKS=OFF
	cmake --build $(FUZZ_BUILD) -j$(JOBS) --target fuzz_proximity fuzz_query

fuzz: fuzz-build
	bash scripts/run-fuzzers.sh $(FUZZ_BUILD) $(FUZZ_SECONDS)

# The motion-planning demo (car-bus, quadrotor-window and arm-shelf problems: out/*.csv, *.json,
# *.svg), then
# the Python example that untangles a 3-D heap of crossing shapes with the signed distance
# (out/untangle_{before,after}.png), and the one that fits capsules and a padded square to an
# L-shaped bracket through the shape-parameter gradients (out/fit.svg).
demo: build
	./$(BUILD)/examples/diffpills_demo out
	PYTHONPATH=$(BUILD)/python MPLBACKEND=Agg $(PYTHON) examples/python/untangle.py out
	PYTHONPATH=$(BUILD)/python $(PYTHON) examples/python/fit_bracket.py out

bench: build
	./$(BUILD)/bench/bench_proximity --benchmark_min_time=0.2
	./$(BUILD)/bench/bench_scene --benchmark_min_time=0.2

format:
	clang-format -i $$(git ls-files '*.cpp' '*.hpp')

clean:
	rm -rf $(BUILD) $(SANITIZE_BUILD) $(FUZZ_BUILD)
