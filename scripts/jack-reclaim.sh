#!/usr/bin/env bash
# Frees JACK's server registry when no JACK server is running. JACK (jackd2) keeps at most 8
# server names in /dev/shm/jack-shm-registry and frees a dead server's slot only when a server
# of the same name registers again, so servers killed with SIGKILL under other names fill it
# until "Too many servers already active". With no jackd or jackdbus process alive every slot is
# stale, and the registry and the dead servers' segments and semaphores are removed; while any
# JACK server runs, nothing is touched.
set -euo pipefail
if pgrep -x 'jackd|jackdbus' >/dev/null 2>&1; then exit 0; fi
rm -f /dev/shm/jack-shm-registry /dev/shm/jack_sem.* /dev/shm/jack_*_[0-9]* 2>/dev/null || true
