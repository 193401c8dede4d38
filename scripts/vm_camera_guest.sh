#!/bin/busybox sh
# /init of the virtual-machine camera bench's guest (packed by scripts/vm_camera_test.sh; see
# docs/DRIVERS.md "The virtual-machine camera bench"). Runs the checks against real kernel drivers
# and reports on the serial console: lines starting with "VMCAM " are the report, "VMCAM EXIT N"
# the verdict (N failed checks), then the machine powers off.
/bin/busybox --install -s /bin
export PATH=/bin:/sbin
mount -t proc proc /proc
mount -t sysfs sysfs /sys
mount -t devtmpfs devtmpfs /dev
mount -t tmpfs tmpfs /tmp
mount -t tmpfs tmpfs /run
exec >/dev/console 2>&1

param() { tr ' ' '\n' </proc/cmdline | sed -n "s/^vmcam\.$1=//p"; }
ACCEL=$(param accel)
FPS=$(param fps)
FRAMES=$(param frames)
failures=0
say() { echo "VMCAM $*"; }
ok() { say "  ok   $*"; }
bad() { say "  FAIL $*"; failures=$((failures + 1)); }
# check "what" COMMAND...: ok when the command succeeds.
check() { what=$1; shift; if "$@"; then ok "$what"; else bad "$what"; fi; }
now() { cut -d' ' -f1 /proc/uptime; }
since() { awk -v a="$1" -v b="$(now)" 'BEGIN { printf "%.1f", b - a }'; }
# field "TEXT" "NAME": the number after NAME in TEXT ("reconnects 1" -> 1).
field() { echo "$1" | grep -o "$2 [0-9.]*" | head -1 | awk '{ print $NF }'; }
finish() {
  say "EXIT $failures"
  sync
  poweroff -f
}

say "guest: kernel $(uname -r), accelerator $ACCEL, $(grep -c ^processor /proc/cpuinfo) CPUs, fps $FPS, frames $FRAMES"

# ============================================================================================
# 1. vivid: a real V4L2 capture driver, and every error-injection control it offers
# ============================================================================================
ctl() { plumb_vmcam_v4l2ctl set /dev/video0 "$1" "$2" || bad "vivid control \"$1\" = $2"; }
load_vivid() {
  modprobe vivid n_devs=1 node_types=0x1 num_inputs=1 input_types=0 vid_cap_nr=0 || return 1
  i=0
  while [ ! -e /dev/video0 ] && [ $i -lt 50 ]; do sleep 0.1; i=$((i + 1)); done
  [ -e /dev/video0 ]
}
vivid_check() {
  t0=$(now)
  say "vivid:"
  load_vivid || { bad "modprobe vivid"; return; }
  plumb_vmcam_v4l2ctl list /dev/video0 >/tmp/vivid_controls.txt
  grep -iE 'inject|disconnect|drop|wrap' /tmp/vivid_controls.txt | sed 's/^/VMCAM     control /'
  printf 'fx 300\nfy 300\ncx 160\ncy 90\nwidth 320\nheight 180\n' >/tmp/vivid_camera.txt

  # An unsupported pixel format and an unsupported size are refused, saying what the driver offers.
  plumb record --source v4l2:/dev/video0:mjpeg --camera /tmp/vivid_camera.txt --out /tmp/x.plumbrec \
    --frames 1 >/tmp/refused.txt 2>&1
  status=$?
  check "mjpeg refused (exit $status): $(cat /tmp/refused.txt)" grep -q "asked for mjpeg 320x180, driver offers" /tmp/refused.txt
  printf 'fx 300\nfy 300\ncx 250\ncy 200\nwidth 500\nheight 400\n' >/tmp/vivid_bad_size.txt
  plumb record --source v4l2:/dev/video0 --camera /tmp/vivid_bad_size.txt --out /tmp/y.plumbrec \
    --frames 1 >/tmp/refused.txt 2>&1
  check "500x400 refused: $(cat /tmp/refused.txt)" grep -q "asked for yuyv 500x400, driver offers" /tmp/refused.txt

  # Capture with every fault vivid can inject, one after the other, while plumb records.
  ctl "Wrap Sequence Number" 1
  ctl "Wrap Timestamp" 1
  plumb record --source v4l2:/dev/video0 --camera /tmp/vivid_camera.txt --out /tmp/vivid.plumbrec \
    --codec raw >/tmp/vivid_record.txt 2>&1 &
  rec=$!
  sleep 2
  ctl "Inject V4L2_BUF_FLAG_ERROR" 1
  sleep 0.5
  ctl "Inject EOS Event" 1
  ctl "Inject Source Change Event" 1
  ctl "Percentage of Dropped Buffers" 30
  sleep 1
  ctl "Percentage of Dropped Buffers" 0
  sleep 0.5
  ctl "Inject VIDIOC_STREAMON Error" 1      # armed: the reopen after the next fault fails once
  ctl "Inject Fatal Streaming Error" 1
  sleep 1.5
  ctl "Inject VIDIOC_PREPARE_BUF Error" 1
  sleep 1.5
  ctl "Disconnect" 1                        # the node goes away like an unplugged camera
  t_gone=$(now)
  sleep 1
  i=0
  while ! rmmod vivid 2>/dev/null && [ $i -lt 50 ]; do sleep 0.1; i=$((i + 1)); done
  load_vivid || bad "vivid reloaded"
  sleep 2.5
  kill -INT $rec
  wait $rec
  status=$?
  cat /tmp/vivid_record.txt
  health=$(grep '^source:' /tmp/vivid_record.txt)
  frames=$(grep -o 'recorded [0-9]* frames' /tmp/vivid_record.txt | awk '{ print $2 }')
  check "plumb record survived every fault and stopped cleanly (exit $status, $frames frames)" [ "$status" -eq 0 ]
  say "  faults counted: errors $(field "$health" errors), reconnects $(field "$health" reconnects) ($(field "$health" "reconnects [0-9]* (") s disconnected), failed reopens $(field "$health" "disconnected, ")"
  say "  driver: error buffers $(field "$health" "error buffers"), frames missing $(field "$health" "frames missing") in $(field "$health" "in") gaps, dequeue-time stamps $(field "$health" "dequeue-time stamps")"
  check "the flagged buffer was dropped and counted" [ "$(field "$health" "error buffers")" -ge 1 ]
  check "dropped buffers counted as missing frames" [ "$(field "$health" "frames missing")" -ge 1 ]
  check "streaming error, STREAMON error, PREPARE_BUF error and disconnect each recovered" \
    [ "$(field "$health" reconnects)" -ge 3 ]
  check "wrapped timestamps replaced by the dequeue time" [ "$(field "$health" "dequeue-time stamps")" -ge 1 ]
  check "frames kept coming after the reload" [ "${frames:-0}" -ge 100 ]
  say "  vivid took $(since "$t0") s"
}

# ============================================================================================
# 2. v4l2loopback: recorded frames through a real capture driver, live vs replay
# ============================================================================================
loopback_check() {
  t0=$(now)
  say "v4l2loopback:"
  modprobe v4l2loopback devices=2 video_nr=10,11 exclusive_caps=1,1 max_buffers=8 \
    card_label="plumb colour,plumb depth" || { bad "modprobe v4l2loopback"; return; }
  d=/tmp/loop
  mkdir -p $d
  plumb_vmcam_feeder feed --source "synth:textured:1:$FRAMES" --colour /dev/video10 --depth /dev/video11 \
    --out-dir $d --fps "$FPS" >$d/feeder.log 2>&1 &
  feeder=$!
  # The capture side exists once the feeder has written a frame (exclusive_caps).
  i=0
  while [ "$(grep -vc '^#' $d/sent.txt 2>/dev/null)" -lt 1 ] && [ $i -lt 100 ]; do sleep 0.1; i=$((i + 1)); done
  plumb run --dataset v4l2:/dev/video10,/dev/video11 --camera $d/camera.txt --out $d/live.txt \
    >$d/live.log 2>&1 &
  live=$!
  wait $feeder
  check "feeder wrote every frame ($(cat $d/feeder.log))" [ $? -eq 0 ]
  # Let plumb finish the frames the driver still holds, then stop it as an operator would.
  sleep $((2 + 20 / FPS))
  kill -INT $live
  wait $live
  live_status=$?
  cat $d/live.log
  check "live run stopped cleanly by SIGINT (exit $live_status, 3 expected)" [ $live_status -eq 3 ]
  match=$(plumb_vmcam_feeder match --sent $d/sent.txt --trajectory $d/live.txt)
  check "every live frame is a frame the feeder sent ($match)" [ $? -eq 0 ]
  first=$(field "$match" first_frame)
  lost=$(field "$match" lost)
  plumb run --dataset $d/replay.plumbrec --skip-frames "$first" --out $d/replay.txt >$d/replay.log 2>&1
  check "replay of the same frames from frame $first" [ $? -eq 0 ]
  live_ate=$(plumb eval --gt $d/groundtruth.txt --est $d/live.txt --json | grep -o '"rmse_m": *[0-9.e-]*' | head -1 | awk '{ print $NF }')
  replay_ate=$(plumb eval --gt $d/groundtruth.txt --est $d/replay.txt --json | grep -o '"rmse_m": *[0-9.e-]*' | head -1 | awk '{ print $NF }')
  health=$(grep '^source:' $d/live.log)
  missing=$(field "$health" "frames missing")
  unpaired_c=$(field "$health" "unpaired colour")
  unpaired_d=$(field "$health" "unpaired depth")
  say "  live ATE $live_ate m, replay ATE $replay_ate m, frames sent from the first live one $(field "$match" sent_from_first), lost $lost"
  say "  lost frames explained: driver sequence gaps $missing, unpaired colour $unpaired_c, unpaired depth $unpaired_d"
  check "live ATE within 5 % of the replay's" awk -v a="$live_ate" -v b="$replay_ate" \
    'BEGIN { exit !(a > 0 && b > 0 && (a - b) / b <= 0.05 && (b - a) / b <= 0.05) }'
  check "every lost frame counted (lost $lost = missing $missing + unpaired colour $unpaired_c)" \
    [ "$lost" -eq $((missing + unpaired_c)) ]
  check "colour and depth paired by kernel timestamps (dequeue-time stamps 0)" \
    [ "$(field "$health" "dequeue-time stamps")" = 0 ]
  say "  v4l2loopback took $(since "$t0") s"
}

# ============================================================================================
# 3. USB: a gadget with a depth camera's identity on dummy_hcd, libusb discovery and hot-plug
# ============================================================================================
GADGET=/sys/kernel/config/usb_gadget/vmcam
make_uvc_gadget() {
  g=$GADGET
  mkdir $g || return 1
  echo 0x8086 >$g/idVendor              # Intel RealSense D435 (drivers/usb/usb_camera_table.cpp)
  echo 0x0b07 >$g/idProduct
  echo 0x0200 >$g/bcdUSB
  echo 0xEF >$g/bDeviceClass            # miscellaneous / interface association, as UVC cameras
  echo 0x02 >$g/bDeviceSubClass
  echo 0x01 >$g/bDeviceProtocol
  mkdir $g/strings/0x409
  echo "Intel(R) RealSense(TM) Depth Camera 435" >$g/strings/0x409/product
  echo "Intel(R) Corporation" >$g/strings/0x409/manufacturer
  echo "vmcam0000001" >$g/strings/0x409/serialnumber
  mkdir $g/configs/c.1 $g/configs/c.1/strings/0x409
  echo "video" >$g/configs/c.1/strings/0x409/configuration
  echo 500 >$g/configs/c.1/MaxPower
  f=$g/functions/uvc.0
  mkdir $f || return 1
  mkdir -p $f/control/header/h
  ln -s $f/control/header/h $f/control/class/fs/h
  ln -s $f/control/header/h $f/control/class/ss/h
  mkdir -p $f/streaming/uncompressed/u/480p
  echo 640 >$f/streaming/uncompressed/u/480p/wWidth
  echo 480 >$f/streaming/uncompressed/u/480p/wHeight
  echo $((640 * 480 * 2)) >$f/streaming/uncompressed/u/480p/dwMaxVideoFrameBufferSize
  echo 333333 >$f/streaming/uncompressed/u/480p/dwDefaultFrameInterval
  printf '333333\n' >$f/streaming/uncompressed/u/480p/dwFrameInterval
  mkdir $f/streaming/header/h
  ln -s $f/streaming/uncompressed/u $f/streaming/header/h/u
  ln -s $f/streaming/header/h $f/streaming/class/fs/h
  ln -s $f/streaming/header/h $f/streaming/class/hs/h
  ln -s $f/streaming/header/h $f/streaming/class/ss/h
  ln -s $f $g/configs/c.1/
}

usb_check() {
  t0=$(now)
  say "usb:"
  modprobe dummy_hcd && modprobe libcomposite && modprobe usb_f_uvc && modprobe uvcvideo ||
    { bad "modprobe dummy_hcd libcomposite usb_f_uvc uvcvideo"; return; }
  mount -t configfs none /sys/kernel/config 2>/dev/null
  check "UVC gadget with a RealSense D435's identity created through configfs" make_uvc_gadget
  udc=$(ls /sys/class/udc | head -1)
  echo "$udc" >$GADGET/UDC
  sleep 1.5
  say "  usb_f_uvc options (no bulk-streaming option in this kernel): $(ls $GADGET/functions/uvc.0 | tr '\n' ' ')"
  plumb devices >/tmp/devices.txt 2>&1
  cat /tmp/devices.txt
  check "plumb devices finds the camera through libusb: $(grep '8086:0b07' /tmp/devices.txt | head -1)" \
    grep -q "usb: 8086:0b07 Intel RealSense D435 at usb" /tmp/devices.txt
  uvc_node=""
  for n in /sys/class/video4linux/video*; do
    grep -q "RealSense" $n/name 2>/dev/null && [ -z "$uvc_node" ] && uvc_node=/dev/$(basename $n)
  done
  say "  uvcvideo bound the gadget: ${uvc_node:-no capture node} ($(dmesg | grep -m1 'uvcvideo.*Found UVC' | sed 's/^\[[^]]*\] //'))"

  # Hot-plug: the camera leaves (UDC unbound) and comes back 2 s later.
  plumb devices --watch 9 >/tmp/watch.txt 2>&1 &
  watch=$!
  sleep 2
  echo "" >$GADGET/UDC
  t_unplug=$(now)
  sleep 2
  echo "$udc" >$GADGET/UDC
  t_replug=$(now)
  wait $watch
  cat /tmp/watch.txt
  check "the departure was reported" grep -q "usb: left 8086:0b07" /tmp/watch.txt
  check "the arrival was reported" grep -q "usb: arrived 8086:0b07" /tmp/watch.txt
  t_left=$(grep -m1 "usb: left 8086:0b07" /tmp/watch.txt | grep -o 'at [0-9.]* s' | awk '{ print $2 }')
  t_arrived=$(grep -m1 "usb: arrived 8086:0b07" /tmp/watch.txt | grep -o 'at [0-9.]* s' | awk '{ print $2 }')
  say "  unplug -> departure event $(awk -v a="$t_unplug" -v b="$t_left" 'BEGIN { printf "%.3f", b - a }') s, replug -> arrival event $(awk -v a="$t_replug" -v b="$t_arrived" 'BEGIN { printf "%.3f", b - a }') s (outage $(awk -v a="$t_left" -v b="$t_arrived" 'BEGIN { printf "%.3f", b - a }') s)"
  say "  usb took $(since "$t0") s"
}

/sbin/systemd-udevd --daemon 2>/dev/null || say "  (systemd-udevd did not start: libusb hears no hot-plug events)"
vivid_check
loopback_check
usb_check
finish
