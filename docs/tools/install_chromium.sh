#!/usr/bin/env bash
# Headless Chromium for `make docs-check` (docs/tools/docs_check.py): Debian's packages chromium and
# fonts-liberation (text in the screenshots). Installed only when missing, as root, with apt-get (no
# upgrade, no recommends; the package lists are refreshed only if the first try fails). Otherwise one
# line says why the browser check is skipped. Never fails: the check itself skips without a browser.
if command -v chromium >/dev/null 2>&1; then
    echo "Chromium: $(command -v chromium) found"
elif [ "$(id -u)" != 0 ] || ! command -v apt-get >/dev/null 2>&1; then
    echo "Chromium: skipped (chromium is not installed; as root on Debian: apt-get install chromium)"
else
    install=(apt-get install -y -qq --no-install-recommends chromium fonts-liberation)
    if DEBIAN_FRONTEND=noninteractive "${install[@]}" >/dev/null 2>&1 ||
       { apt-get update -qq >/dev/null 2>&1 && DEBIAN_FRONTEND=noninteractive "${install[@]}" >/dev/null 2>&1; }; then
        echo "Chromium: installed ($(command -v chromium))"
    else
        echo "Chromium: skipped (apt-get install chromium failed)"
    fi
fi
exit 0
