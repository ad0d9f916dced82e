# SPDX-License-Identifier: MIT
# Worst stack depth of call chains from GCC's -fcallgraph-info=su graphs (.ci files, VCG).
#   awk -v roots="main,coa_predict" -v indirect="f,g" -f callgraph.awk *.ci
# For each root: the largest sum of frames along a call chain below it, and that chain.
# An indirect call may reach any of the functions named in `indirect` (the callbacks the
# core hands libccd); an entry CALLER>TARGET names a function that only CALLER's indirect
# calls reach (a handler table, a callback the caller was given). Calls that leave the graph (libc, libm, libgcc: built without
# -fstack-usage) are listed; their frames are not in the sums. Recursion makes the depth
# unbounded: it is reported and the exit status is 1.
function strip(s) { gsub(/^"|"$/, "", s); return s }
function field(line, key,   i, s) {
    i = index(line, key ": \"")
    if (i == 0) return ""
    s = substr(line, i + length(key) + 3)
    return substr(s, 1, index(s, "\"") - 1)
}
function shortname(t,   n, p) { n = split(t, p, ":"); return p[n] }
/^node:/ {
    t = field($0, "title"); l = field($0, "label")
    if (l ~ /[0-9]+ bytes \(/) {
        b = l; sub(/ bytes \(.*/, "", b); sub(/.*\\n/, "", b)
        size[t] = b + 0; defined[t] = 1; byname[shortname(t)] = t
        if (l ~ /\(dynamic\)/) dynamic[t] = 1
    }
    next
}
/^edge:/ {
    s = field($0, "sourcename"); d = field($0, "targetname")
    if (!((s, d) in seen)) { seen[s, d] = 1; nout[s]++; out[s, nout[s]] = d }
}
function resolve(t) {
    if (t in defined) return t
    if (t in byname) return byname[t]
    return ""
}
function worst(n,   i, k, t, r, w, best, c, cands) {
    if (n in memo) return memo[n]
    if (n in onstack) { cyclic[n] = 1; return 0 }
    onstack[n] = 1; best = 0; nextof[n] = ""
    for (i = 1; i <= nout[n]; i++) {
        t = out[n, i]
        if (t == "__indirect_call") {
            c = split(indirect, cands, ",")
            for (k = 1; k <= c; k++) {
                target = cands[k]
                if (index(target, ">") > 0) {
                    if (substr(target, 1, index(target, ">") - 1) != shortname(n)) continue
                    target = substr(target, index(target, ">") + 1)
                }
                r = resolve(target)
                if (r == "") { missing[target] = 1; continue }
                w = worst(r)
                if (w > best) { best = w; nextof[n] = r }
            }
            continue
        }
        r = resolve(t)
        if (r == "") { external[t] = 1; continue }
        w = worst(r)
        if (w > best) { best = w; nextof[n] = r }
    }
    delete onstack[n]
    memo[n] = size[n] + best
    return memo[n]
}
END {
    status = 0
    nr = split(roots, rs, ",")
    for (i = 1; i <= nr; i++) {
        r = resolve(rs[i])
        if (r == "") { printf "callgraph: root %s not found\n", rs[i]; status = 1; continue }
        total = worst(r); chain = ""
        for (n = r; n != ""; n = nextof[n]) chain = chain (chain == "" ? "" : " > ") shortname(n) "(" size[n] ")"
        printf "%-20s %6d bytes: %s\n", rs[i], total, chain
    }
    for (n in cyclic) { printf "callgraph: recursion through %s: unbounded\n", shortname(n); status = 1 }
    for (n in dynamic) { printf "callgraph: dynamic frame in %s: unbounded\n", shortname(n); status = 1 }
    for (n in missing) { printf "callgraph: indirect target %s not found\n", n; status = 1 }
    ext = ""
    for (n in external) ext = ext " " n
    if (ext != "") printf "not counted (library functions, frames unknown):%s\n", ext
    exit status
}
