#!/usr/bin/env bash
# Installs the Debian packages fastcal builds against, when they are missing, and the
# de_DE.UTF-8 locale the locale-independence test runs under. Idempotent and quiet when
# everything is present. Needs root (or sudo) to install.
set -euo pipefail
packages=(cmake g++ make libceres-dev libeigen3-dev libgflags-dev libgoogle-glog-dev
          libyaml-cpp-dev libgtest-dev libbenchmark-dev
          libssl-dev  # libcrypto: SHA-256 of the input files (provenance)
          help2man  # the man pages, from each command's --help
          pkgconf  # pkg-config: the C interface's fastcal.pc, used by its example's test
          zlib1g-dev  # zlib: every reader takes gzipped files (telemetry kept as .csv.gz)
          libhowardhinnant-date-dev  # date/date.h: ISO 8601 time stamps of column maps
          libspectra-dev  # Spectra (headers): shift-invert Lanczos for the lowest modes
          # The Python module: pybind11's headers and CMake package, Python's headers,
          # NumPy; pytest runs its tests, matplotlib the plot of docs/python.md.
          pybind11-dev python3-dev python3-numpy python3-pytest python3-matplotlib
          # Optional at run time: .xlsx exports (openpyxl) and DataFrames (pandas) in
          # fastcal.read_dataset / Dataset.from_dataframe; installed so their tests run.
          python3-openpyxl python3-pandas
          # fastcal.track(client=...): each window's fold a task on a Dask cluster (its
          # tests run a two-worker LocalCluster on the loopback interface).
          python3-dask python3-distributed
          locales)  # de_DE.UTF-8: tests/calibration_test.cc, decimal comma
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
# A locale whose decimal separator is a comma, for the test that numbers are read and
# written the same in every locale (it skips, saying why, when none is installed).
comma_locale=de_DE.UTF-8
need_locale=0
locale -a 2>/dev/null | grep -qix 'de_DE\.utf-\?8' || need_locale=1
[ ${#missing[@]} -eq 0 ] && [ $need_locale -eq 0 ] && exit 0
sudo_cmd=()
if [ "$(id -u)" -ne 0 ]; then
  if ! command -v sudo >/dev/null; then
    [ ${#missing[@]} -eq 0 ] || { echo "setup: need root to install ${missing[*]}" >&2; exit 1; }
    echo "setup: need root to generate $comma_locale; its test will skip" >&2
    exit 0
  fi
  sudo_cmd=(sudo)
fi
export DEBIAN_FRONTEND=noninteractive
if [ ${#missing[@]} -gt 0 ]; then
  echo "setup: installing ${missing[*]}" >&2
  "${sudo_cmd[@]}" apt-get update -qq
  "${sudo_cmd[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
fi
if [ $need_locale -eq 1 ]; then
  echo "setup: generating the $comma_locale locale" >&2
  "${sudo_cmd[@]}" sed -i "s/^# *\($comma_locale UTF-8\)/\1/" /etc/locale.gen
  grep -q "^$comma_locale UTF-8" /etc/locale.gen ||
    echo "$comma_locale UTF-8" | "${sudo_cmd[@]}" tee -a /etc/locale.gen >/dev/null
  "${sudo_cmd[@]}" locale-gen >/dev/null
fi
