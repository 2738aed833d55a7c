"""Support every layer uses: errors, parameter checks, atomic writes, output guards, the native
engine's loading, digests, index runs, fresh memory and overlay colours."""
