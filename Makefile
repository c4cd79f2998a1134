# The README's two commands: `make demo` and `make test`. Both install the Debian packages they
# need first (scripts/install-deps.sh, only what is missing).
BUILD ?= build
SANITIZE_BUILD ?= build-sanitize
JOBS ?= 2

.PHONY: all deps build test test-sanitize demo bench format clean

all: build

deps:
	@bash scripts/install-deps.sh

build: deps
	cmake -S . -B $(BUILD) -DCMAKE_BUILD_TYPE=Release
	cmake --build $(BUILD) -j$(JOBS)

# Every test, then the whole suite once more under AddressSanitizer + UndefinedBehaviorSanitizer.
test: build
	ctest --test-dir $(BUILD) --output-on-failure
	$(MAKE) test-sanitize

test-sanitize: deps
	cmake -S . -B $(SANITIZE_BUILD) -DCMAKE_BUILD_TYPE=RelWithDebInfo -DDIFFPILLS_SANITIZE=ON \
	  -DDIFFPILLS_BUILD_BENCHMARKS=OFF
	cmake --build $(SANITIZE_BUILD) -j$(JOBS)
	ASAN_OPTIONS=detect_leaks=1 UBSAN_OPTIONS=print_stacktrace=1 \
	  ctest --test-dir $(SANITIZE_BUILD) --output-on-failure -LE no_sanitize

# The motion-planning demo: solves the car-bus problem, writes out/*.csv, *.json, *.svg.
demo: build
	./$(BUILD)/examples/diffpills_demo out

bench: build
	./$(BUILD)/bench/bench_proximity --benchmark_min_time=0.2

format:
	clang-format -i $$(git ls-files '*.cpp' '*.hpp')

clean:
	rm -rf $(BUILD) $(SANITIZE_BUILD)
