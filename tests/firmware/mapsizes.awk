# SPDX-License-Identifier: MIT
# Flash and RAM of a GNU ld map file by origin: the core, libccd, the messages (LCM's
# coders and src/lcm's validation), the drivers' message checks (src/auth), libsodium's
# primitives, the vehicle protocol (src/protocol), its replay and link (src/replay), the
# firmware's own objects (the firmware's, the check's, the replay's or the vehicle's), and
# newlib with libgcc (everything else). Input sections only: the linker's alignment padding
# is not counted (the ELF's totals include it).
#   awk -f mapsizes.awk coavoid-firmware.map
function hex(h,   n, k) {
    n = 0; h = tolower(substr(h, 3))
    for (k = 1; k <= length(h); k++) n = n * 16 + index("0123456789abcdef", substr(h, k, 1)) - 1
    return n
}
/^Linker script and memory map/ { inmap = 1; next }
!inmap { next }
/^ ?\.[A-Za-z_]/ || /^ COMMON/ {
    s = $1
    if (s ~ /^\.(text|rodata|isr_vector|ARM\.ex)/) kind = "flash"
    else if (s ~ /^\.data/) kind = "data"
    else if (s ~ /^\.bss/ || s == "COMMON") kind = "bss"
    else kind = ""
}
kind != "" {
    for (i = 1; i + 2 <= NF; i++) {
        if ($i ~ /^0x[0-9a-f]+$/ && $(i + 1) ~ /^0x[0-9a-f]+$/ && $(i + 2) ~ /\.(o|obj)\)?$/) {
            f = $(i + 2)
            if (f ~ /libcoavoid_core\.a/) c = "core"
            else if (f ~ /libccd\.a/) c = "libccd"
            else if (f ~ /libcoavoid_sodium_arm\.a/) c = "libsodium"
            else if (f ~ /libcoavoid_auth\.a/) c = "auth"
            else if (f ~ /libcoavoid_lcm(types)?\.a/) c = "messages"
            else if (f ~ /libcoavoid_protocol\.a/) c = "protocol"
            else if (f ~ /libcoavoid_replay\.a/) c = "replay"
            else if (f ~ /coavoid_firmware(_check|_replay|_vehicle)?\.dir/) c = "firmware"
            else c = "newlib+libgcc"
            total[c, kind] += hex($(i + 1))
            break
        }
    }
}
END {
    split("core libccd messages auth libsodium protocol replay firmware newlib+libgcc", order, " ")
    printf "%-14s %8s %8s %8s\n", "", "flash", "data", "bss"
    for (j = 1; j <= 9; j++)
        printf "%-14s %8d %8d %8d\n", order[j], total[order[j], "flash"], total[order[j], "data"], total[order[j], "bss"]
}
