#!/usr/bin/env bash
# Thin wrapper kept for muscle memory: the layer check is scripts/check_layers.py (Python 3 standard
# library). Usage: scripts/check_layers.sh [SOURCE_DIR]
exec python3 "$(dirname "$0")/check_layers.py" "$@"
