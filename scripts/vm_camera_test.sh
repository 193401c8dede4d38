#!/usr/bin/env bash
# The virtual-machine camera bench (ctest `vm_camera`; docs/DRIVERS.md "The virtual-machine camera
# bench"): plumb against real Linux camera drivers without a camera.
#
#   bash scripts/vm_camera_test.sh [BUILD_DIR]      (default: build; needs bin/plumb and the
#                                                   bench/vmcam programs built there)
#
# On the host: downloads Debian's kernel package for linux-image-amd64 (and its headers and the
# v4l2loopback-dkms source) with `apt-get download` and extracts them with `dpkg-deb -x` into
# BUILD_DIR/vm_camera/ (nothing is installed on the host), builds v4l2loopback against those headers,
# packs an initramfs (busybox-static, the modules and their dependencies, plumb, the bench programs,
# udevd for libusb hot-plug events, every shared library ldd names) and boots it with
# qemu-system-x86_64: KVM when /dev/kvm opens, TCG otherwise (at a lower frame rate). The guest
# (scripts/vm_camera_guest.sh) runs the checks: vivid (+ every error-injection control),
# v4l2loopback (live vs replay ATE, lost frames; with the USB check selected, the camera's USB
# identity unplugged mid-run and plugged in again 2 s later) and USB (dummy_hcd gadget, libusb,
# hot-plug, which virtual USB path carries UVC video). Its
# report comes back over the serial console; the exit code is the guest's verdict.
#
# Environment:
#   PLUMB_VM_CAMERA=0   disable the bench: prints why and exits 77 (ctest: skipped). Nothing else
#                       skips: a missing prerequisite is a failure that says what to install.
#   PLUMB_VM_ACCEL      kvm | tcg | auto (default auto: kvm when /dev/kvm can be opened)
#   PLUMB_VM_CACHE      where the downloaded .deb files are kept (default BUILD_DIR/vm_camera/cache)
#   PLUMB_VM_TIMEOUT    seconds before the guest is killed (default 480 with KVM, 1500 with TCG)
#   PLUMB_VM_ONLY       run only some checks: any of vivid, loop, usb (default all)
set -euo pipefail
start_s=$(date +%s.%N)
root="$(cd "$(dirname "$0")/.." && pwd)"
build="$(cd "${1:-$root/build}" && pwd)"
work="$build/vm_camera"
cache="${PLUMB_VM_CACHE:-$work/cache}"

if [ "${PLUMB_VM_CAMERA:-1}" = "0" ]; then
  echo "SKIP vm_camera: disabled by PLUMB_VM_CAMERA=0"
  exit 77
fi
fail() { echo "vm_camera: FAIL: $*" >&2; exit 1; }
elapsed() { awk -v a="$1" -v b="$(date +%s.%N)" 'BEGIN { printf "%.1f", b - a }'; }

# --- prerequisites: a clear failure, never a silent skip -------------------------------------
missing=()
for tool in qemu-system-x86_64:qemu-system-x86 cpio:cpio depmod:kmod dpkg-deb:dpkg apt-get:apt \
            apt-cache:apt make:make gcc-12:gcc-12 udevadm:udev; do
  command -v "${tool%%:*}" >/dev/null 2>&1 || missing+=("${tool##*:}")
done
[ -x /bin/busybox ] && ! ldd /bin/busybox >/dev/null 2>&1 || missing+=(busybox-static)
if [ ${#missing[@]} -gt 0 ]; then
  fail "missing ${missing[*]} (bash scripts/install_deps.sh installs them; PLUMB_VM_CAMERA=0 disables the bench)"
fi
for program in plumb plumb_vmcam_feeder plumb_vmcam_v4l2ctl plumb_vmcam_uvc_gadget plumb_vmcam_usbip; do
  [ -x "$build/bin/$program" ] || fail "$build/bin/$program not built (cmake --build $build)"
done

# --- the guest kernel: Debian's linux-image-amd64, downloaded and extracted, never installed --------
mkdir -p "$cache" "$work"
image_pkg=$(apt-cache depends linux-image-amd64 2>/dev/null | awk '/Depends: linux-image-[0-9]/ { print $2; exit }')
if [ -z "$image_pkg" ] && [ "$(id -u)" = 0 ]; then
  apt-get update -qq >/dev/null 2>&1 || true
  image_pkg=$(apt-cache depends linux-image-amd64 2>/dev/null | awk '/Depends: linux-image-[0-9]/ { print $2; exit }')
fi
[ -n "$image_pkg" ] || fail "apt-cache cannot resolve linux-image-amd64 (run apt-get update)"
kver="${image_pkg#linux-image-}"                     # 6.1.0-56-amd64
kabi="${kver%-amd64}"                                # 6.1.0-56
kmajor=$(echo "$kver" | cut -d. -f1-2)               # 6.1
packages=("$image_pkg" "linux-headers-$kver" "linux-headers-$kabi-common" "linux-kbuild-$kmajor" v4l2loopback-dkms)
t0=$(date +%s.%N)
for p in "${packages[@]}"; do
  if ! ls "$cache/${p}_"*.deb >/dev/null 2>&1; then
    (cd "$cache" && apt-get download -q "$p" >/dev/null 2>"$cache/download.log") ||
      fail "apt-get download $p failed: $(tail -2 "$cache/download.log")"
  fi
done
kroot="$work/kernel-$kver"
if [ ! -f "$kroot/.extracted" ]; then
  rm -rf "$kroot"
  mkdir -p "$kroot"
  for p in "${packages[@]}"; do dpkg-deb -x "$(ls "$cache/${p}_"*.deb | tail -1)" "$kroot"; done
  # The headers' Makefile includes the common tree by absolute path: point it into the extraction.
  sed -i "s|^include /usr/src/|include $kroot/usr/src/|" "$kroot/usr/src/linux-headers-$kver/Makefile"
  depmod -b "$kroot" "$kver"
  touch "$kroot/.extracted"
fi
echo "vm_camera: kernel $kver ($(elapsed "$t0") s to fetch and extract)"

# --- accelerator: KVM only if it really boots this kernel ---------------------------------------
# /dev/kvm may open and still not run a stock kernel: under PVM (kvm_pvm, a nested-virtualization
# module of some cloud machines) a Debian kernel hangs at its first instruction. So a short boot
# probe must print the kernel's banner before KVM is used.
accel="${PLUMB_VM_ACCEL:-auto}"
kvm_reason=""
kvm_boots() {
  if ! python3 -c 'import fcntl, os, sys; sys.exit(0 if fcntl.ioctl(os.open("/dev/kvm", os.O_RDWR), 0xAE00) == 12 else 1)' \
      2>/dev/null; then  # 0xAE00: KVM_GET_API_VERSION, 12 when KVM works
    kvm_reason="/dev/kvm cannot be opened ($(ls -l /dev/kvm 2>&1))"
    return 1
  fi
  if [ -d /sys/module/kvm_pvm ]; then  # known not to boot stock kernels: save the 30 s probe
    kvm_reason="this host's KVM is kvm_pvm, which runs only PVM-enabled guest kernels"
    return 1
  fi
  timeout 30 qemu-system-x86_64 -enable-kvm -cpu host,-arch-capabilities -m 256 -nographic -no-reboot \
    -kernel "$kroot/boot/vmlinuz-$kver" -append "console=ttyS0 earlyprintk=serial,ttyS0 panic=-1 init=/none" \
    </dev/null >"$work/kvm_probe.log" 2>&1
  if grep -q "Linux version" "$work/kvm_probe.log"; then return 0; fi
  kvm_reason="/dev/kvm opens but $kver does not boot under it within 30 s ($work/kvm_probe.log)"
  return 1
}
t0=$(date +%s.%N)
case "$accel" in
  auto) if kvm_boots; then accel=kvm; else accel=tcg; fi ;;
  kvm) kvm_boots || fail "PLUMB_VM_ACCEL=kvm: $kvm_reason" ;;
  tcg) kvm_reason="PLUMB_VM_ACCEL=tcg" ;;
  *) fail "PLUMB_VM_ACCEL must be kvm, tcg or auto" ;;
esac
[ "$accel" = tcg ] && echo "vm_camera: TCG emulation (lower frame rate, fewer frames): $kvm_reason"
echo "vm_camera: accelerator $accel ($(elapsed "$t0") s to decide)"

# --- v4l2loopback, built against the guest kernel's headers --------------------------------------
t0=$(date +%s.%N)
loop_src=$(ls -d "$kroot"/usr/src/v4l2loopback-* | tail -1)
loop_ko="$work/v4l2loopback-$kver/v4l2loopback.ko"
if [ ! -f "$loop_ko" ]; then
  rm -rf "$work/v4l2loopback-$kver"
  cp -r "$loop_src" "$work/v4l2loopback-$kver"
  make -s -C "$kroot/usr/src/linux-headers-$kver" M="$work/v4l2loopback-$kver" CC=gcc-12 modules \
    >"$work/v4l2loopback-build.log" 2>&1 || fail "v4l2loopback build failed: $(tail -5 "$work/v4l2loopback-build.log")"
fi
echo "vm_camera: v4l2loopback $(basename "$loop_src") built for $kver ($(elapsed "$t0") s)"

# --- frames for the v4l2loopback check: a synthetic scene rendered here, natively ----------------
if [ "$accel" = kvm ]; then
  # arch-capabilities off: some nested KVM hosts refuse its MSR (0x10a) and qemu aborts.
  accel_flags=(-enable-kvm -cpu host,-arch-capabilities)
  guest_fps=10 guest_frames=120 timeout_s="${PLUMB_VM_TIMEOUT:-480}"
else
  accel_flags=(-accel tcg -cpu max)
  guest_fps=1 guest_frames=30 timeout_s="${PLUMB_VM_TIMEOUT:-1500}"
fi
t0=$(date +%s.%N)
synth="$work/synth-$guest_frames"
if [ ! -f "$synth/groundtruth.txt" ]; then
  rm -rf "$synth"
  "$build/bin/plumb" synth --out "$synth" --preset textured --seed 1 --frames "$guest_frames" >/dev/null ||
    fail "plumb synth failed"
fi
echo "vm_camera: synthetic scene, $guest_frames frames ($(elapsed "$t0") s)"

# --- initramfs ---------------------------------------------------------------------------------------
t0=$(date +%s.%N)
initrd="$work/initramfs"
rm -rf "$initrd"
mkdir -p "$initrd"/{bin,sbin,dev,proc,sys,tmp,run,etc,vmcam,lib/modules/"$kver"/extra}
cp /bin/busybox "$initrd/bin/busybox"
cp "$root/scripts/vm_camera_guest.sh" "$initrd/init"
chmod +x "$initrd/init"
modules=(vivid v4l2loopback-deps dummy_hcd libcomposite usb_f_uvc usb_f_ss_lb uvcvideo usbip-vudc vhci-hcd usbip-core)
mdir="$kroot/lib/modules/$kver"
copy_module() {  # the module and everything modules.dep says it needs
  local line
  line=$(grep -E "(^|/)$1\.ko:" "$mdir/modules.dep" || true)
  [ -n "$line" ] || fail "module $1 not in $kver"
  for m in ${line/:/}; do
    mkdir -p "$initrd/lib/modules/$kver/$(dirname "$m")"
    cp -n "$mdir/$m" "$initrd/lib/modules/$kver/$m"
  done
}
for m in "${modules[@]}"; do
  [ "$m" = v4l2loopback-deps ] && m=videodev
  copy_module "$m"
done
cp "$loop_ko" "$initrd/lib/modules/$kver/extra/"
cp "$mdir"/modules.{order,builtin,builtin.modinfo} "$initrd/lib/modules/$kver/"
depmod -b "$initrd" "$kver"
# Programs and every shared library they load.
guest_programs=("$build/bin/plumb" "$build/bin/plumb_vmcam_feeder" "$build/bin/plumb_vmcam_v4l2ctl"
                "$build/bin/plumb_vmcam_uvc_gadget" "$build/bin/plumb_vmcam_usbip")
for p in "${guest_programs[@]}"; do cp "$p" "$initrd/bin/"; done
cp "$(readlink -f "$(command -v udevadm)")" "$initrd/sbin/udevadm"
ln -s udevadm "$initrd/sbin/systemd-udevd"
for p in "${guest_programs[@]}" "$initrd/sbin/udevadm"; do
  ldd "$p" | grep -q "not found" && fail "$p: $(ldd "$p" | grep 'not found' | head -1)"
  for lib in $(ldd "$p" | awk '/=> \// { print $3 } /^\t\/lib/ { print $1 }'); do
    mkdir -p "$initrd$(dirname "$lib")"
    cp -nL "$lib" "$initrd$lib"
  done
done
cp -r "$synth" "$initrd/vmcam/synth"
printf 'root:x:0:0:root:/:/bin/sh\n' >"$initrd/etc/passwd"
printf 'root:x:0:\n' >"$initrd/etc/group"
(cd "$initrd" && find . | cpio -o -H newc --quiet) >"$work/initramfs.cpio"
echo "vm_camera: initramfs $(du -m "$work/initramfs.cpio" | cut -f1) MiB ($(elapsed "$t0") s)"

# --- boot ------------------------------------------------------------------------------------------
log="$work/console.log"
t0=$(date +%s.%N)
set +e
timeout "$timeout_s" qemu-system-x86_64 "${accel_flags[@]}" -m 2048 -smp 2 -nographic -no-reboot \
  -kernel "$kroot/boot/vmlinuz-$kver" -initrd "$work/initramfs.cpio" \
  -append "console=ttyS0 quiet loglevel=4 panic=-1 vmcam.accel=$accel vmcam.fps=$guest_fps vmcam.only=${PLUMB_VM_ONLY:-all}" \
  </dev/null >"$log" 2>&1
qemu_status=$?
set -e
tr -d '\r' <"$log" | grep '^VMCAM' | sed 's/^VMCAM //' || true
boot_s=$(elapsed "$t0")
[ $qemu_status -eq 124 ] && fail "the guest did not finish within $timeout_s s (console: $log)"
verdict=$(tr -d '\r' <"$log" | awk '/^VMCAM EXIT / { print $3 }' | tail -1)
echo "vm_camera: accelerator $accel, guest run $boot_s s, total $(elapsed "$start_s") s"
[ -n "$verdict" ] || fail "the guest gave no verdict (qemu exit $qemu_status; console: $log)"
[ "$verdict" = 0 ] || fail "guest checks failed (exit $verdict; console: $log)"
echo "vm_camera: PASS"
