# Two entry points for a fresh machine (see README): `make demo` and `make test`.
PYTHON ?= python3
VENV := .venv
BIN := $(VENV)/bin

.PHONY: demo test install examples clean sound browser

$(BIN)/pianobot: pyproject.toml
	$(PYTHON) -m venv $(VENV)
	$(BIN)/pip install --quiet --upgrade pip
	$(BIN)/pip install --quiet torch==2.13.0  # the local CPU wheel; must come before anything that needs torch
	$(BIN)/pip install --quiet -e ".[test]"
	touch $(BIN)/pianobot

install: $(BIN)/pianobot

demo: install
	mkdir -p out
	$(BIN)/pianobot play examples/midi/twinkle.mid -o out/twinkle.mid --video out/twinkle.mp4 --html out/twinkle.html  # the paper's per-phrase SAC policies in models/
	$(BIN)/pianobot play examples/midi/ode-to-joy-performed.mid -o out/ode-to-joy-pianist.mid --video out/ode-to-joy-pianist.mp4 --html out/ode-to-joy-pianist.html  # both hands: the pianist's five-finger hands, a two-hand file's default (their packaged general policy)
	@echo "open out/twinkle.html and out/ode-to-joy-pianist.html in a browser (they work offline): the video with its sound, the piano roll, every note"

test: install
	$(BIN)/ruff check .
	$(BIN)/ruff format --check .
	$(BIN)/python -m pytest

examples: install
	$(BIN)/python examples/make_examples.py

clean:
	rm -rf $(VENV) *.egg-info

# A piano sound for --wav and --video: the FluidSynth library and a small General MIDI soundfont
# (Debian packages; needs root); pyfluidsynth comes with the venv. Without them, pianobot
# synthesises sine waves (pianobot/perform/audio.py's SOUND names these packages).
SOUND_PACKAGES := libfluidsynth3 timgm6mb-soundfont
sound:
	@if command -v apt-get >/dev/null 2>&1 && [ "$$(id -u)" = 0 ]; then \
		timeout 300 apt-get install -y -q $(SOUND_PACKAGES) >/dev/null 2>&1 || \
		(timeout 300 apt-get update -q >/dev/null 2>&1 && timeout 300 apt-get install -y -q $(SOUND_PACKAGES) >/dev/null 2>&1) || \
		echo "could not install FluidSynth: --wav and --video use sine waves"; \
	else echo "install $(SOUND_PACKAGES) (Debian packages) for a piano sound"; fi

# A headless browser for the HTML report's test (tests/test_report.py): Debian's chromium (needs
# root). Without it, that test is skipped and says so.
browser:
	@if command -v chromium >/dev/null 2>&1; then :; \
	elif command -v apt-get >/dev/null 2>&1 && [ "$$(id -u)" = 0 ]; then \
		timeout 600 apt-get install -y -q chromium >/dev/null 2>&1 || \
		(timeout 300 apt-get update -q >/dev/null 2>&1 && timeout 600 apt-get install -y -q chromium >/dev/null 2>&1) || \
		echo "could not install chromium: the HTML report's browser test is skipped"; \
	else echo "install chromium (Debian package) for the HTML report's browser test"; fi
