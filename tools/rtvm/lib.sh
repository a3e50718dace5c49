# shellcheck shell=bash
# Functions of tools/rtvm/run (sourced; expects PROJ, CACHE, VERBOSE, say).

RTVM_MODULES="virtio_pci 9pnet_virtio 9p"

# The PREEMPT_RT kernel to boot, as "VERSION ROOT": ROOT/boot/vmlinuz-VERSION
# and ROOT/lib/modules/VERSION. Installed (ROOT /) first, else one that
# install-deps unpacked to RTVM_KERNEL_DIR on a host with a boot loader.
rtvm_find_kernel() {
    local img ver root best="" installed=()
    [ "${RTVM_KERNEL_MODE:-}" = extract ] || installed=(/boot/vmlinuz-*-rt-*)
    for img in "${installed[@]}" "${RTVM_KERNEL_DIR:-/opt/ncpar-rtvm}"/*/boot/vmlinuz-*-rt-*; do
        [ -r "$img" ] || continue
        ver=${img##*/vmlinuz-}
        root=${img%/boot/vmlinuz-*}
        [ -n "$root" ] || root=/
        if [ -d "$root/lib/modules/$ver" ]; then
            best="$ver $root"
            [ "$root" = / ] && break
        fi
    done
    [ -n "$best" ] && echo "$best"
}

# Copies one module into the initramfs as a plain .ko: busybox insmod
# cannot read compressed ones.
rtvm_put_module() {
    local src=$1 dst
    dst=$2/$(basename "${1%.xz}")
    dst=${dst%.zst}
    case $src in
        *.xz) xz -dc "$src" >"$dst" ;;
        *.zst) zstd -qdc "$src" >"$dst" ;;
        *) cp "$src" "$dst" ;;
    esac
    basename "$dst"
}

# Builds (once per kernel and init script) a tiny initramfs: static busybox,
# the virtio/9p modules in load order and guest-init. Prints its path.
rtvm_initramfs() {
    local kver=$1 kroot=$2 out=$CACHE/initramfs-$1.cpio.gz
    if [ -s "$out" ] && [ "$out" -nt "$HERE/guest-init" ] \
        && [ "$out" -nt "$HERE/lib.sh" ]; then
        echo "$out"
        return 0
    fi
    local root m path order=""
    root=$(mktemp -d "$CACHE/initramfs.XXXXXX")
    mkdir -p "$root/bin" "$root/mod"
    cp /bin/busybox "$root/bin/busybox" || { rm -rf "$root"; return 1; }
    cp "$HERE/guest-init" "$root/init"
    chmod 755 "$root/init"
    for m in $RTVM_MODULES; do
        while read -r _ path _; do
            case " $order " in *" $path "*) continue ;; esac
            order="$order $path"
        done < <(modprobe -d "$kroot" -S "$kver" --show-depends "$m" | grep '^insmod ')
    done
    for path in $order; do
        rtvm_put_module "$path" "$root/mod" >>"$root/mod/order"
    done
    (cd "$root" && find . | busybox cpio -o -H newc 2>/dev/null) \
        | gzip -1 >"$out.tmp" && mv "$out.tmp" "$out"
    rm -rf "$root"
    [ -s "$out" ] && echo "$out"
}

# KVM only if this kernel really boots under it here: a paravirtual KVM may
# refuse the stock RT kernel. The verdict is cached per host and guest kernel.
rtvm_pick_accel() {
    local kver=$1 kroot=$2 initrd=$3 probe verdict kvm=${RTVM_KVM_DEV:-/dev/kvm}
    if [ ! -w "$kvm" ]; then
        say "no usable $kvm: using TCG"
        echo tcg
        return
    fi
    probe=$CACHE/kvm-probe-$kver-$(uname -r)
    if [ ! -s "$probe" ]; then
        say "probing whether KVM boots $kver (once; cached in $probe)"
        if VERBOSE=0 rtvm_boot "$kver" "$kroot" "$initrd" kvm 45 true >/dev/null 2>&1; then
            echo kvm >"$probe"
        else
            echo tcg >"$probe"
        fi
    fi
    verdict=$(cat "$probe")
    [ "$verdict" = kvm ] || say "KVM cannot boot $kver here (probe cached in $probe): using TCG"
    echo "$verdict"
}

# Keeps the streamed guest output readable: no CRs, no terminal controls.
rtvm_filter() {
    sed -u -e 's/\x1b\[[0-9;?]*[ -\/]*[@-~]//g' -e 's/\x1b[()][0-9A-Za-z]//g' \
        -e 's/\x1b[=>78c]//g' -e 's/\r//g'
}

rtvm_boot() {
    local kver=$1 kroot=$2 initrd=$3 accel=$4 timeout=$5
    shift 5
    local res accel_args kmods=() rc status
    res=$(mktemp -d "$CACHE/run.XXXXXX")
    {
        printf 'RTVM_PROJ=%q\nRTVM_ACCEL=%q\n' "$PROJ" "$accel"
        # An unpacked kernel's modules are laid over the host's /lib/modules.
        [ "$kroot" = / ] || echo RTVM_KMODS=1
    } >"$res/config"
    [ "$kroot" = / ] || kmods=(-virtfs
        "local,path=$kroot/lib/modules,mount_tag=kmods,security_model=none,readonly=on")
    { printf 'exec'; printf ' %q' "$@"; echo; } >"$res/cmd"
    echo "$*" >"$res/cmdline"
    # shellcheck disable=SC2054  # the commas are qemu's option syntax
    case $accel in
        kvm) accel_args=(-accel kvm -cpu host -smp 2 -m 2048) ;;
        *) accel_args=(-accel tcg,thread=multi -cpu max -smp 2 -m 2048) ;;
    esac
    set +e
    timeout -k 5 "$timeout" qemu-system-x86_64 -nodefaults -no-user-config \
        -display none -no-reboot "${accel_args[@]}" \
        -kernel "${kroot%/}/boot/vmlinuz-$kver" -initrd "$initrd" \
        -append "console=ttyS0 panic=-1 loglevel=5" \
        -serial "file:$res/console.log" \
        -chardev stdio,id=out,signal=off -serial chardev:out \
        -virtfs local,path=/,mount_tag=hostroot,security_model=none,readonly=on,multidevs=remap \
        -virtfs "local,path=$PROJ,mount_tag=proj,security_model=none,multidevs=remap" \
        -virtfs "local,path=$res,mount_tag=res,security_model=none" "${kmods[@]}" \
        </dev/null 2>"$res/qemu.err" | rtvm_filter
    rc=${PIPESTATUS[0]}
    set -e
    cp -f "$res/console.log" "$CACHE/last-console.log" 2>/dev/null || true
    status=$(cat "$res/status" 2>/dev/null || true)
    if [ "$rc" = 124 ] || [ "$rc" = 137 ]; then
        say "TIMEOUT: guest still running after ${timeout}s, killed" \
            "(kernel log: $CACHE/last-console.log)"
        [ "$VERBOSE" = 1 ] && tail -20 "$res/console.log" >&2
        rm -rf "$res"
        return 124
    fi
    if [ -z "$status" ]; then
        say "guest ended without running the command (qemu exit $rc)"
        cat "$res/qemu.err" >&2
        tail -20 "$res/console.log" >&2 2>/dev/null
        rm -rf "$res"
        return 125
    fi
    [ "$VERBOSE" = 1 ] && cat "$res/console.log" >&2
    rm -rf "$res"
    return "$status"
}
