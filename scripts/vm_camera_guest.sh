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
ONLY=$(param only)
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
# before "TEXT" "NAME": the number before NAME ("5 failed reopens" -> 5).
before() { echo "$1" | grep -o "[0-9.]* $2" | head -1 | awk '{ print $1 }'; }
finish() {
  say "EXIT $failures"
  sync
  poweroff -f
}

say "guest: kernel $(uname -r), accelerator $ACCEL, $(grep -c ^processor /proc/cpuinfo) CPUs, fps $FPS, checks: $ONLY"

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

  # Capture while every control vivid 6.1 offers for faults is pulled, one after the other.
  plumb record --source v4l2:/dev/video0 --camera /tmp/vivid_camera.txt --out /tmp/vivid.plumbrec \
    --codec raw >/tmp/vivid_record.txt 2>&1 &
  rec=$!
  sleep 1
  ctl "Wrap Sequence Number" 1              # from the next STREAMON: the counter starts below 2^32
  ctl "Wrap Timestamp" 1                    # from the next STREAMON: stamps far off CLOCK_MONOTONIC
  sleep 1
  ctl "Inject V4L2_BUF_FLAG_ERROR" 1        # one buffer comes back flagged damaged
  ctl "Inject req_validate() Error" 1       # media requests: plumb uses none, so no effect
  ctl "Percentage of Dropped Buffers" 30
  sleep 1
  ctl "Percentage of Dropped Buffers" 0
  sleep 0.5
  ctl "Inject VIDIOC_QBUF Error" 1          # the next requeue fails
  sleep 1.5
  ctl "Inject VIDIOC_REQBUFS Error" 1       # armed: the next reopen fails at REQBUFS ...
  ctl "Inject VIDIOC_STREAMON Error" 1      # ... and the one after at STREAMON
  ctl "Inject Fatal Streaming Error" 1      # the queue fails now (DQBUF: EIO)
  sleep 2
  # The node goes away like an unplugged camera; vivid registers it again once its last user has
  # closed it (plumb does, on the error), as a replugged camera comes back.
  ctl "Disconnect" 1
  sleep 3
  kill -INT $rec
  wait $rec
  status=$?
  cat /tmp/vivid_record.txt
  health=$(grep '^source:' /tmp/vivid_record.txt)
  frames=$(grep -o 'recorded [0-9]* frames' /tmp/vivid_record.txt | awk '{ print $2 }')
  check "plumb record survived every fault and stopped cleanly (exit $status, $frames frames)" [ "$status" -eq 0 ]
  say "  faults counted: errors $(field "$health" errors), reconnects $(field "$health" reconnects) ($(before "$health" "s disconnected") s disconnected), failed reopens $(before "$health" "failed reopens")"
  say "  driver: error buffers $(field "$health" "error buffers"), frames missing $(field "$health" "frames missing") in $(before "$health" gaps) gaps, dequeue-time stamps $(field "$health" "dequeue-time stamps")"
  check "the flagged buffer was dropped and counted" [ "$(field "$health" "error buffers")" -ge 1 ]
  check "dropped buffers counted as missing frames" [ "$(field "$health" "frames missing")" -ge 1 ]
  check "QBUF error, fatal streaming error (+ REQBUFS and STREAMON errors on reopen) and disconnect recovered" \
    [ "$(field "$health" reconnects)" -ge 3 ]
  check "the REQBUFS and STREAMON errors failed a reopen each" [ "$(before "$health" "failed reopens")" -ge 2 ]
  check "wrapped timestamps replaced by the dequeue time, kernel stamps used otherwise" \
    [ "$(field "$health" "dequeue-time stamps")" -ge 1 ] && [ "$(field "$health" "dequeue-time stamps")" -lt "${frames:-0}" ]
  check "frames kept coming after the disconnect" [ "${frames:-0}" -ge 100 ]
  say "  vivid took $(since "$t0") s"
}

# ============================================================================================
# 2. v4l2loopback: recorded frames through a real capture driver, live vs replay
# ============================================================================================
# json_number FILE NAME: the number after "NAME": in a --stats file (null and absent: empty).
json_number() { grep -o "\"$2\": *[0-9.e-]*" "$1" | head -1 | sed 's/.*: *//'; }

# The hot-plug half of the loopback check, after the run: what plumb heard, what it counted, what
# happened to tracking. Uses the loopback check's variables (d, t_unplug, t_replug, health).
hotplug_report() {
  say "  hot-plug (identity: dummy_hcd gadget 8086:0b07; video: v4l2loopback, paused with the unbind):"
  grep -E 'usb camera left|woken by a hot-plug|reconnected|reopen failed' $d/live.log | sed 's/^ */VMCAM     /'
  say "  $(grep feeder: $d/feeder.log | tail -1)"
  say "  frames received (sent index): $(awk '{ printf "%s ", $1 }' $d/received.txt)"
  left_line=$(grep -m1 'usb camera left' $d/live.log)
  woken_line=$(grep -m1 'woken by a hot-plug arrival' $d/live.log)
  t_left=$(echo "$left_line" | grep -o 't=[0-9.]*' | cut -d= -f2)
  t_woken=$(echo "$woken_line" | grep -o 't=[0-9.]*' | cut -d= -f2)
  check "plumb heard the departure through libusb and reported the disconnect ($(echo $left_line))" [ -n "$t_left" ]
  check "the reconnection was woken by the libusb arrival ($(echo $woken_line))" [ -n "$t_woken" ]
  # The loopback nodes could be reopened at any time (they never went away): only the wait for
  # the arrival keeps the reopen after it.
  t_reconnected=$(awk '/usb camera left/ { left = 1 } left && /reconnected/ { print; exit }' $d/live.log |
    grep -o 't=[0-9.]*' | cut -d= -f2)
  check "the reopen came after the arrival, none before (reconnected at t=$t_reconnected, arrival t=$t_woken; failed reopens $(before "$health" "failed reopens"))" \
    awk -v r="${t_reconnected:-0}" -v w="${t_woken:-1e30}" -v f="$(before "$health" "failed reopens")" \
    'BEGIN { exit !(r >= w && f == 0) }'
  s=$d/live.json
  outage=$(json_number $s longest_outage_s)
  reconnect=$(json_number $s arrival_to_first_frame_s)
  slowest=$(grep -A1 '"ms_per_frame"' $s | grep -o '"max": *[0-9.]*' | sed 's/.*: *//')
  tracked_after=$(awk -v t="${t_woken:-1e30}" '!/^#/ && $1 > t' $d/live.txt | wc -l)
  say "  unbind -> departure heard $(awk -v a="$t_unplug" -v b="$t_left" 'BEGIN { printf "%.2f", b - a }') s; bind -> arrival heard $(awk -v a="$t_replug" -v b="$t_woken" 'BEGIN { printf "%.2f", b - a }') s (+ <= 20 ms to notice)"
  say "  --stats source_supervision: outages $(json_number $s outages), usb departures $(json_number $s usb_departures), usb arrivals $(json_number $s usb_arrivals), reconnects $(json_number $s reconnects), disconnected $(json_number $s disconnected_s) s, longest outage $outage s"
  say "  reconnect time: arrival event -> first frame ${reconnect:-none} s (at ${FPS} Hz the next frame is up to $(awk -v f="$FPS" 'BEGIN { printf "%.1f", 1 / f }') s away), + tracking it (slowest frame ${slowest:-?} ms): first tracked frame <= $(awk -v r="${reconnect:-0}" -v m="${slowest:-0}" 'BEGIN { printf "%.3f", r + m / 1000 }') s after the arrival"
  say "  after the reconnect: $tracked_after poses; tracking lost $(grep -o '"lost": *[0-9]*' $s | head -1 | sed 's/.*: *//') frame(s) in the run, relocalizations $(json_number $s relocalizations)"
  check "--stats counts the outage (outages 1, usb departures 1) and its length (longest outage $outage s, unplugged 2 s)" \
    awk -v o="$(json_number $s outages)" -v u="$(json_number $s usb_departures)" -v l="${outage:-0}" \
    'BEGIN { exit !(o == 1 && u == 1 && l >= 1.8 && l <= 10) }'
  check "a reconnect time was measured" [ -n "$reconnect" ]
  check "tracking went on after the reconnect ($tracked_after poses after the arrival, the last line a pose)" \
    sh -c "[ $tracked_after -ge 2 ] && ! tail -1 $d/live.txt | grep -q '^#'"
}

loopback_check() {
  t0=$(now)
  say "v4l2loopback:"
  modprobe v4l2loopback devices=2 video_nr=10,11 exclusive_caps=1,1 max_buffers=8 \
    card_label="plumb colour,plumb depth" || { bad "modprobe v4l2loopback"; return; }
  d=/tmp/loop
  mkdir -p $d
  # Hot-plug (with the usb check): the camera's USB identity is the dummy_hcd gadget of check 3,
  # its video comes through v4l2loopback (no virtual USB path carries UVC video, check 3). Mid-run
  # the harness unplugs both together: the feeder pauses (--pause-while) and the UDC is unbound;
  # 2 s later the UDC is bound again and the feeder resumes. plumb knows the camera by its VID:PID
  # (@usb=) and must hear the departure and the arrival through libusb.
  hotplug=0
  usb_spec=""
  case "$ONLY" in *all*|*usb*) hotplug=1 ;; esac
  if [ $hotplug = 1 ]; then
    if camera_gadget_bound; then
      usb_spec="@usb=8086:0b07"
    else
      bad "hot-plug: the camera gadget enumerated on dummy_hcd"
      hotplug=0
    fi
  fi
  plumb_vmcam_feeder feed --source /vmcam/synth --colour /dev/video10 --depth /dev/video11 \
    --out-dir $d --fps "$FPS" --hold 1 --wait-for $d/go --pause-while $d/unplugged >$d/feeder.log 2>&1 &
  feeder=$!
  # The capture side exists once the feeder has written a frame (exclusive_caps).
  i=0
  while [ $i -lt 1200 ]; do
    n=$(grep -vc '^#' $d/sent.txt 2>/dev/null)
    [ "${n:-0}" -ge 1 ] && break
    sleep 0.1
    i=$((i + 1))
  done
  # Deterministic mode, as the replay (v4l2loopback lets a reader fall only 2 frames behind
  # before it skips to the newest: a slow frame costs frames, which are counted).
  plumb run --dataset "v4l2:/dev/video10,/dev/video11$usb_spec" --camera $d/camera.txt --out $d/live.txt \
    --stats $d/live.json >$d/live.log 2>&1 &
  live=$!
  # The feeder shows its first view until plumb has mapped the depth node's buffers (both nodes
  # are then set up; it streams right after), then plays the sequence.
  i=0
  while ! grep -q /dev/video11 /proc/$live/maps 2>/dev/null && kill -0 $live 2>/dev/null && [ $i -lt 600 ]; do
    sleep 0.1
    i=$((i + 1))
  done
  touch $d/go
  if [ $hotplug = 1 ]; then
    # Unplugged halfway through the sequence, for 2 s.
    sent_at_go=$(grep -vc '^#' $d/sent.txt)
    half=$(( $(grep -vc '^#' /vmcam/synth/groundtruth.txt) / 2 ))
    i=0
    while [ "$(grep -vc '^#' $d/sent.txt)" -lt $((sent_at_go + half)) ] && kill -0 $live 2>/dev/null && [ $i -lt 3000 ]; do
      sleep 0.1
      i=$((i + 1))
    done
    touch $d/unplugged
    t_unplug=$(now)
    echo "" >$CONFIGFS/camera/UDC
    sleep 2
    t_replug=$(now)
    echo dummy_udc.0 >$CONFIGFS/camera/UDC
    rm $d/unplugged
  fi
  # After the last frame the feeder keeps sending it (the camera goes on looking at its last
  # view); plumb gets a few frame periods to take what is queued, then it is stopped as an
  # operator would, and then the feeder.
  i=0
  while ! grep -q "feeder: wrote" $d/feeder.log && kill -0 $feeder 2>/dev/null && [ $i -lt 3000 ]; do
    sleep 0.2
    i=$((i + 1))
  done
  check "feeder wrote every frame ($(head -1 $d/feeder.log))" grep -q "feeder: wrote" $d/feeder.log
  sleep $((1 + 4 / FPS))
  kill -INT $live
  wait $live
  live_status=$?
  kill -TERM $feeder
  wait $feeder
  check "feeder ended cleanly ($(tail -1 $d/feeder.log))" [ $? -eq 0 ]
  cat $d/live.log
  check "live run stopped cleanly by SIGINT (exit $live_status, 3 expected)" [ $live_status -eq 3 ]
  match=$(plumb_vmcam_feeder match --sent $d/sent.txt --trajectory $d/live.txt --received-out $d/received.txt)
  check "every live frame is a frame the feeder sent, by its kernel timestamp ($match)" [ $? -eq 0 ]
  reconnects=$(field "$(grep '^source:' $d/live.log)" reconnects)
  [ "$(field "$match" restamped)" = 0 ] ||
    say "  $(field "$match" restamped) frame(s) carried the time of a VIDIOC_REQBUFS of plumb's (v4l2loopback re-stamps its buffers then: at the start and at each of the $reconnects reopen(s))"
  check "re-stamped frames: at most one per REQBUFS" [ "$(field "$match" restamped)" -le $((1 + reconnects)) ]
  first=$(field "$match" first_frame)
  lost=$(field "$match" lost)
  # The replay of exactly the frames the live run received (and, for reference, of every frame
  # sent from the first one it received).
  plumb_vmcam_feeder select --recording $d/replay.plumbrec --indices $d/received.txt --out $d/received.plumbrec
  plumb run --dataset $d/received.plumbrec --out $d/replay.txt >$d/replay.log 2>&1
  check "replay of the frames the live run received" [ $? -eq 0 ]
  plumb run --dataset $d/replay.plumbrec --skip-frames "$first" --out $d/replay_all.txt >$d/replay_all.log 2>&1
  check "replay of every frame sent from frame $first" [ $? -eq 0 ]
  ate() { plumb eval --gt $d/groundtruth.txt --est "$1" --json | grep -o '"rmse_m": *[0-9.e-]*' | head -1 | awk '{ print $NF }'; }
  live_ate=$(ate $d/live.txt)
  replay_ate=$(ate $d/replay.txt)
  replay_all_ate=$(ate $d/replay_all.txt)
  health=$(grep '^source:' $d/live.log)
  missing=$(field "$health" "frames missing")
  unpaired_c=$(field "$health" "unpaired colour")
  unpaired_d=$(field "$health" "unpaired depth")
  say "  live ATE $live_ate m, replay of the same frames $replay_ate m (of every frame sent, none lost: $replay_all_ate m); live frames $(field "$match" live_frames) (sent frames $(field "$match" first_frame)..$(field "$match" last_frame); the feeder's $(grep -o 'wrote [0-9]*' $d/feeder.log | awk '{ print $2 }') frames and then its last view), lost $lost"
  say "  live:   $(grep 'ms per frame' $d/live.log)"
  say "  replay: $(grep 'ms per frame' $d/replay.log)"
  # A colour frame given back without a depth partner leaves a gap in the delivered sequence just
  # like a frame the driver overwrote before plumb read it: both are in "frames missing".
  say "  lost frames explained: sequence gaps $missing; pairing gave back $unpaired_c colour and $unpaired_d depth frames without a partner (also before the first frame it delivered)"
  check "live ATE within 5 % of the replay's" awk -v a="$live_ate" -v b="$replay_ate" \
    'BEGIN { exit !(a > 0 && b > 0 && (a - b) / b <= 0.05 && (b - a) / b <= 0.05) }'
  # With the hot-plug: the frames the camera never sent while unplugged are missing too; plumb
  # infers them from the time gap across the reopen (a camera's counter restarts), to the frame
  # rounded, so they may differ by one per reopen.
  not_sent=$(grep -o '[0-9]* frame(s) never sent' $d/feeder.log | awk '{ print $1 }')
  not_sent=${not_sent:-0}
  check "every lost frame counted (sequence gaps $missing = lost $lost + $not_sent never sent while unplugged, within one per reopen: $reconnects)" \
    awk -v m="$missing" -v l="$lost" -v n="$not_sent" -v r="${reconnects:-0}" \
    'BEGIN { d = m - l - n; if (d < 0) d = -d; exit !(d <= r) }'
  check "colour and depth paired by kernel timestamps (dequeue-time stamps 0)" \
    [ "$(field "$health" "dequeue-time stamps")" = 0 ]
  [ $hotplug = 1 ] && hotplug_report
  say "  v4l2loopback took $(since "$t0") s"
}

# ============================================================================================
# 3. USB: a gadget with a depth camera's identity on dummy_hcd, libusb discovery and hot-plug
# ============================================================================================
CONFIGFS=/sys/kernel/config/usb_gadget
# make_gadget NAME FUNCTION: a gadget with a RealSense D435's identity (drivers/usb/usb_camera_table.cpp)
# and one function: uvc (a UVC camera: control + streaming interfaces, YUYV 320x240 at 15 Hz) or
# sourcesink (bulk interfaces, for controllers UVC cannot bind to).
make_gadget() {
  g=$CONFIGFS/$1
  mkdir $g || return 1
  echo 0x8086 >$g/idVendor
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
  if [ "$2" = uvc ]; then
    f=$g/functions/uvc.0
    mkdir $f || return 1
    mkdir -p $f/control/header/h
    ln -s $f/control/header/h $f/control/class/fs/h
    ln -s $f/control/header/h $f/control/class/ss/h
    echo 3072 >$f/streaming_maxpacket      # 3 x 1024 bytes per microframe (high speed)
    fr=$f/streaming/uncompressed/u/240p
    mkdir -p $fr
    echo 320 >$fr/wWidth
    echo 240 >$fr/wHeight
    echo $((320 * 240 * 2)) >$fr/dwMaxVideoFrameBufferSize
    echo 666666 >$fr/dwDefaultFrameInterval
    echo 666666 >$fr/dwFrameInterval
    mkdir $f/streaming/header/h
    ln -s $f/streaming/uncompressed/u $f/streaming/header/h/u
    for speed in fs hs ss; do ln -s $f/streaming/header/h $f/streaming/class/$speed/h; done
  else
    f=$g/functions/SourceSink.0
    mkdir $f || return 1
  fi
  ln -s $f $g/configs/c.1/
}

# wait_camera present|absent: until a USB device 8086:0b07 is (not) enumerated, at most 30 s.
wait_camera() {
  i=0
  while [ $i -lt 150 ]; do
    if grep -qs 0b07 /sys/bus/usb/devices/*/idProduct; then found=present; else found=absent; fi
    [ $found = "$1" ] && return 0
    sleep 0.2
    i=$((i + 1))
  done
  return 1
}

# The uvcvideo capture node of the gadget camera (its V4L2 name is the product string).
uvc_capture_node() {
  for n in /sys/class/video4linux/video*; do
    if grep -q "RealSense" $n/name 2>/dev/null && [ "$(cat $n/index 2>/dev/null)" = 0 ]; then
      echo /dev/$(basename $n)
      return
    fi
  done
}
# The gadget side's video output node (usb_f_uvc names it after the UDC).
uvc_gadget_node() {
  for n in /sys/class/video4linux/video*; do
    grep -qE "udc|vudc" $n/name 2>/dev/null && { echo /dev/$(basename $n); return; }
  done
}

usb_modules() {
  modprobe dummy_hcd && modprobe libcomposite && modprobe usb_f_uvc && modprobe usb_f_ss_lb &&
    modprobe uvcvideo || { bad "modprobe dummy_hcd libcomposite usb_f_uvc usb_f_ss_lb uvcvideo"; return 1; }
  mount -t configfs none /sys/kernel/config 2>/dev/null
  return 0
}

# The D435-identity gadget (bulk interfaces) bound to dummy_hcd and enumerated: made once, used by
# the loopback check's hot-plug and by the usb check.
camera_gadget_bound() {
  usb_modules || return 1
  [ -d $CONFIGFS/camera ] || make_gadget camera sourcesink || { bad "gadget created through configfs"; return 1; }
  [ "$(cat $CONFIGFS/camera/UDC)" = dummy_udc.0 ] && return 0
  t_bind=$(now)
  echo dummy_udc.0 >$CONFIGFS/camera/UDC
  wait_camera present || return 1
  say "  the camera gadget enumerated on dummy_hcd after $(since "$t_bind") s"
}

usb_check() {
  t0=$(now)
  say "usb:"
  # (a) Discovery and hot-plug on dummy_hcd, with the same identity over bulk interfaces.
  camera_gadget_bound || { bad "the gadget enumerated on dummy_hcd"; return; }
  dmesg | grep -E 'usb 1-1' | tail -5
  plumb devices >/tmp/devices.txt 2>&1
  cat /tmp/devices.txt
  check "plumb devices finds the camera through libusb: $(grep '8086:0b07' /tmp/devices.txt | head -1)" \
    grep -q "usb: 8086:0b07 Intel RealSense D435 at usb" /tmp/devices.txt
  plumb devices --watch 12 >/tmp/watch.txt 2>&1 &
  watch=$!
  sleep 2
  t_unplug=$(now)  # /proc/uptime: CLOCK_BOOTTIME, the monotonic clock here (no suspend), 10 ms steps
  echo "" >$CONFIGFS/camera/UDC
  sleep 2
  t_replug=$(now)
  echo dummy_udc.0 >$CONFIGFS/camera/UDC
  wait_camera present
  sleep 1
  kill -INT $watch
  wait $watch
  cat /tmp/watch.txt
  check "the departure was reported" grep -q "usb: left 8086:0b07" /tmp/watch.txt
  check "the arrival was reported" grep -q "usb: arrived 8086:0b07" /tmp/watch.txt
  t_left=$(grep -m1 "usb: left 8086:0b07" /tmp/watch.txt | grep -o 'at [0-9.]* s' | awk '{ print $2 }')
  t_arrived=$(grep -m1 "usb: arrived 8086:0b07" /tmp/watch.txt | grep -o 'at [0-9.]* s' | awk '{ print $2 }')
  if [ -n "$t_left" ] && [ -n "$t_arrived" ]; then
    say "  unplug -> departure event $(awk -v a="$t_unplug" -v b="$t_left" 'BEGIN { printf "%.3f", b - a }') s, replug -> arrival event $(awk -v a="$t_replug" -v b="$t_arrived" 'BEGIN { printf "%.3f", b - a }') s (outage seen by libusb $(awk -v a="$t_left" -v b="$t_arrived" 'BEGIN { printf "%.3f", b - a }') s)"
  fi
  echo "" >$CONFIGFS/camera/UDC

  # (b) Can dummy_hcd carry a UVC camera? Its controller has no isochronous endpoint, and 6.1's
  # usb_f_uvc streams only isochronously (its options have no bulk mode), so the bind fails.
  make_gadget uvcdummy uvc || bad "UVC gadget created through configfs"
  say "  usb_f_uvc options: $(ls $CONFIGFS/uvcdummy/functions/uvc.0 | tr '\n' ' ')"
  echo dummy_udc.0 >$CONFIGFS/uvcdummy/UDC 2>/dev/null
  sleep 0.5
  if [ "$(cat $CONFIGFS/uvcdummy/UDC)" = dummy_udc.0 ]; then
    say "  UVC gadget bound to dummy_udc.0"
  else
    say "  UVC gadget cannot bind to dummy_udc.0: $(dmesg | grep -m1 'Unable to allocate streaming EP' | sed 's/^\[[^]]*\] //')"
  fi
  echo "" >$CONFIGFS/uvcdummy/UDC 2>/dev/null  # a failed bind stays pending on the UDC otherwise

  # (c) UVC video over USB/IP: the UVC gadget on usbip-vudc, attached to vhci-hcd over loopback TCP.
  ip link set lo up
  modprobe usbip-vudc && modprobe vhci-hcd || { bad "modprobe usbip-vudc vhci-hcd"; return; }
  echo usbip-vudc.0 >$CONFIGFS/uvcdummy/UDC 2>/dev/null
  sleep 0.5
  if [ "$(cat $CONFIGFS/uvcdummy/UDC)" != usbip-vudc.0 ]; then
    say "  UVC gadget cannot bind to usbip-vudc.0: $(dmesg | grep 'Unable to allocate streaming EP\|vudc' | tail -1 | sed 's/^\[[^]]*\] //')"
  else
    gadget_node=$(uvc_gadget_node)
    plumb_vmcam_uvc_gadget --device "$gadget_node" --seconds 40 >/tmp/uvc_gadget.txt 2>&1 &
    served=$!
    plumb_vmcam_usbip
    sleep 3
    capture=$(uvc_capture_node)
    dmesg | grep -iE 'uvc|vhci|vudc|usb 3-|usb 2-' | tail -12
    say "  UVC over USB/IP: gadget node ${gadget_node:-none}, uvcvideo capture node ${capture:-none}"
    if [ -n "$capture" ]; then
      printf 'fx 262\nfy 262\ncx 159.5\ncy 119.5\nwidth 320\nheight 240\n' >/tmp/uvc_camera.txt
      echo 0x80 >/sys/module/uvcvideo/parameters/trace  # UVC_DBG_FRAME: why frames are dropped
      plumb record --source v4l2:$capture --camera /tmp/uvc_camera.txt --out /tmp/uvc.plumbrec --codec raw \
        --frames 20 >/tmp/uvc_record.txt 2>&1 &
      rec=$!
      sleep 15
      kill -INT $rec 2>/dev/null
      wait $rec
      cat /tmp/uvc_record.txt
      mount -t debugfs none /sys/kernel/debug 2>/dev/null
      for st in /sys/kernel/debug/usb/uvcvideo/*/stats; do say "  uvcvideo stream statistics:"; sed 's/^/VMCAM     /' $st; done
      say "  uvcvideo frame log: $(dmesg | grep -c 'isochronous frame lost') isochronous frames lost; first lines:"
      dmesg | grep -iE 'frame lost|Non-zero status|Dropping|payload|FID' | head -8 | sed 's/^/VMCAM     /' 
    fi
    kill $served 2>/dev/null
    wait $served
    cat /tmp/uvc_gadget.txt
  fi
  say "  usb took $(since "$t0") s"
}

/sbin/systemd-udevd --daemon 2>/dev/null || say "  (systemd-udevd did not start: libusb hears no hot-plug events)"
case "$ONLY" in *all*|*vivid*) vivid_check ;; esac
case "$ONLY" in *all*|*loop*) loopback_check ;; esac
case "$ONLY" in *all*|*usb*) usb_check ;; esac
finish
