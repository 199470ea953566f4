// Random valid ps_1_x arithmetic programs for differential tests (test_executor_reference.cpp
// against an exact reference, test_executor_fast.cpp fast path against the generic path): a
// small structured program model, its assembly text, random inputs and a generator that mostly
// produces programs ps11::validate accepts (the callers filter out the rest).
#pragma once

#include <algorithm>
#include <array>
#include <cstdint>
#include <cstdio>
#include <optional>
#include <random>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "ps11/assembler.h"
#include "ps11/validator.h"

namespace execrand {

// ---------------------------------------------------------------- program model
enum Op { MOV, ADD, SUB, MUL, MAD, DP3, DP4, LRP, CND, CMP, NOPS };
inline const char* kOpName[] = {"mov", "add", "sub", "mul", "mad", "dp3", "dp4", "lrp", "cnd", "cmp"};
inline const int kOpSrcs[] = {1, 2, 2, 2, 3, 2, 2, 3, 3, 3};

enum RegT { R, C, V, T };
inline const char kRegChar[] = {'r', 'c', 'v', 't'};

// modifiers: 0 none, 1 neg, 2 bias, 3 -bias, 4 bx2, 5 -bx2, 6 comp (1-), 7 x2, 8 -x2
struct Src {
    RegT type = R;
    int index = 0;
    int mod = 0;
    int sel = -1;  // -1: no selector; else replicate component
};
struct Ins {
    Op op = MOV;
    bool coissue = false;
    RegT dtype = R;
    int dindex = 0;
    int mask = 15;  // bit c = component c
    int shift = 0;  // -3..3
    bool sat = false;
    Src s[3];
};
struct TexIns {  // texcoord tN (1_1-1_3) or texcrd rD.mask, tN[.xyw] (1_4)
    int dindex = 0;
    int tindex = 0;
    int mask = 7;
    bool xyw = false;
};
struct Prog {
    int minor = 1;
    std::vector<std::array<float, 4>> defs;  // (index in w? no) see defIndex
    std::vector<int> defIndex;
    std::vector<TexIns> tex;
    std::vector<Ins> ins;
};

inline std::string srcText(const Src& s) {
    std::string reg = std::string(1, kRegChar[s.type]) + std::to_string(s.index);
    std::string out;
    switch (s.mod) {
        case 0: out = reg; break;
        case 1: out = "-" + reg; break;
        case 2: out = reg + "_bias"; break;
        case 3: out = "-" + reg + "_bias"; break;
        case 4: out = reg + "_bx2"; break;
        case 5: out = "-" + reg + "_bx2"; break;
        case 6: out = "1-" + reg; break;
        case 7: out = reg + "_x2"; break;
        case 8: out = "-" + reg + "_x2"; break;
    }
    if (s.sel >= 0) out += std::string(".") + "rgba"[s.sel];
    return out;
}
inline std::string maskText(int mask) {
    if (mask == 15) return "";
    std::string m = ".";
    for (int c = 0; c < 4; ++c)
        if (mask & (1 << c)) m += "rgba"[c];
    return m;
}
inline std::string floatText(float f) {
    char buf[64];
    std::snprintf(buf, sizeof buf, "%.9g", double(f));
    return buf;
}
inline std::string progText(const Prog& p) {
    std::ostringstream o;
    o << "ps_1_" << p.minor << "\n";
    for (size_t i = 0; i < p.defs.size(); ++i) {
        o << "def c" << p.defIndex[i];
        for (float f : p.defs[i]) o << ", " << floatText(f);
        o << "\n";
    }
    for (const TexIns& t : p.tex) {
        if (p.minor < 4)
            o << "texcoord t" << t.tindex << "\n";
        else
            o << "texcrd r" << t.dindex << maskText(t.mask) << ", t" << t.tindex << (t.xyw ? ".xyw" : ".xyz")
              << "\n";
    }
    static const char* shiftName[] = {"_d8", "_d4", "_d2", "", "_x2", "_x4", "_x8"};
    for (const Ins& in : p.ins) {
        o << (in.coissue ? "+" : "") << kOpName[in.op] << shiftName[in.shift + 3] << (in.sat ? "_sat" : "") << " "
          << kRegChar[in.dtype] << in.dindex << maskText(in.mask);
        for (int i = 0; i < kOpSrcs[in.op]; ++i) o << ", " << srcText(in.s[i]);
        o << "\n";
    }
    return o.str();
}

// ---------------------------------------------------------------- inputs
struct Inputs {
    std::array<float, 4> consts[8];
    std::array<float, 4> color[2];
    std::array<float, 4> tc[8];
};


// ---------------------------------------------------------------- random programs
struct Gen {
    std::mt19937 rng;
    explicit Gen(uint32_t seed) : rng(seed) {}
    int uni(int lo, int hi) { return std::uniform_int_distribution<int>(lo, hi)(rng); }
    bool coin(double p) { return std::uniform_real_distribution<double>(0, 1)(rng) < p; }

    // A grid-friendly or arbitrary float in [lo, hi].
    float value(float lo, float hi) {
        switch (uni(0, 5)) {
            case 0: return float(uni(0, 255)) / 255.0f * (hi - lo) + lo;
            case 1: return float(uni(int(lo * 8), int(hi * 8))) / 8.0f;  // exact halves, quarters: ties
            case 2: return float(uni(0, 510)) / 510.0f;                   // half-way between 8-bit levels
            case 3: return float(uni(int(lo * 4080), int(hi * 4080))) / 4080.0f;
            default: return std::uniform_real_distribution<float>(lo, hi)(rng);
        }
    }
    Inputs inputs() {
        Inputs in;
        for (auto& c : in.consts)
            for (float& f : c) f = coin(0.1) ? value(-2.0f, 2.0f) : value(-1.0f, 1.0f);
        for (auto& c : in.color)
            for (float& f : c) f = coin(0.05) ? value(-0.5f, 1.5f) : value(0.0f, 1.0f);
        for (auto& c : in.tc)
            for (float& f : c) f = value(-1.5f, 1.5f);
        return in;
    }

    // Source registers readable with these component needs (bit mask of components read).
    Prog program(int minor) {
        Prog p;
        p.minor = minor;
        const bool v14 = minor == 4;
        const int nTemps = v14 ? 6 : 2;
        // defined[type][index] = bit mask of defined components
        int defined[4][8] = {};
        for (int i = 0; i < 8; ++i) defined[C][i] = 15;
        for (int i = 0; i < 2; ++i) defined[V][i] = 15;
        int ndefs = uni(0, 2);
        for (int d = 0; d < ndefs; ++d) {
            p.defIndex.push_back(uni(0, 7));
            std::array<float, 4> val;
            for (float& f : val) f = coin(0.15) ? value(-2.0f, 2.0f) : value(-1.0f, 1.0f);
            p.defs.push_back(val);
        }
        int ntex = uni(0, 2);
        for (int i = 0; i < ntex; ++i) {
            TexIns t;
            t.tindex = i == 0 ? uni(0, 1) : uni(2, 3);
            if (v14) {
                t.dindex = uni(0, 5);
                t.mask = coin(0.5) ? 7 : 3;
                t.xyw = coin(0.5);
                // texcrd .rg leaves b undefined
                defined[R][t.dindex] |= t.mask;
            } else {
                defined[T][t.tindex] = 15;
            }
            p.tex.push_back(t);
        }
        int portLimit[4] = {2, 2, 2, minor >= 2 ? 3 : 2};  // R C V T
        if (v14) portLimit[R] = 3, portLimit[T] = 1;
        int slots = uni(1, 7), used = 0;
        for (int s = 0; s < slots && used < slots; ++s) {
            bool pair = coin(0.3);
            int n = pair ? 2 : 1;
            bool alphaFirst = coin(0.5);
            std::vector<Ins> group;
            std::set<std::pair<int, int>> pairUsed;
            int defAfter[4][8];
            std::copy(&defined[0][0], &defined[0][0] + 32, &defAfter[0][0]);
            for (int m = 0; m < n; ++m) {
                Ins in;
                in.coissue = m == 1;
                int opHi = minor >= 2 ? CMP : CND;
                in.op = Op(uni(0, opHi));
                if (minor < 2 && in.op == DP4) in.op = DP3;
                if (pair && in.op == DP4) in.op = MUL;
                // mask
                if (pair) {
                    bool rgb = (m == 0) != alphaFirst;
                    in.mask = rgb ? 7 : 8;
                    if (!rgb && in.op == DP3) in.op = MAD;
                } else if (v14) {
                    in.mask = coin(0.5) ? 15 : uni(1, 15);
                } else {
                    int pick = uni(0, 2);
                    in.mask = pick == 0 ? 15 : pick == 1 ? 7 : 8;
                }
                if (!v14 && in.op == DP3 && in.mask == 8) in.mask = 7;
                // destination
                if (!v14 && defined[T][0] + defined[T][1] + defined[T][2] + defined[T][3] && coin(0.15)) {
                    in.dtype = T;
                    in.dindex = uni(0, 3);
                } else {
                    in.dtype = R;
                    in.dindex = coin(0.5) ? 0 : uni(0, nTemps - 1);
                }
                // modifiers
                in.sat = coin(0.3);
                int sh = uni(0, 9);
                if (sh < 5) in.shift = 0;
                else if (v14) in.shift = std::array<int, 6>{1, 2, 3, -1, -2, -3}[uni(0, 5)];
                else in.shift = std::array<int, 3>{1, 2, -1}[uni(0, 2)];
                // sources
                if (!v14 && in.op == CND && !(defined[R][0] & 8)) in.op = MAD;
                std::set<std::pair<int, int>> insUsed;
                for (int i = 0; i < kOpSrcs[in.op]; ++i) {
                    Src& src = in.s[i];
                    if (!v14 && in.op == CND && i == 0) {
                        src.type = R, src.index = 0, src.sel = 3, src.mod = 0;
                        insUsed.insert({R, 0});
                        pairUsed.insert({R, 0});
                        continue;
                    }
                    int need = (in.op == DP3) ? 7 : (in.op == DP4 ? 15 : in.mask);
                    if (v14 && coin(0.25)) {
                        src.sel = uni(0, 3);
                    } else if (!v14 && in.mask == 8 && coin(0.3)) {
                        src.sel = coin(0.5) ? 3 : 2;
                    } else if (!v14 && coin(0.1)) {
                        src.sel = 3;
                    }
                    int needBits = src.sel >= 0 ? (1 << src.sel) : need;
                    // candidates
                    std::vector<std::pair<RegT, int>> cand;
                    for (int t = 0; t < 4; ++t)
                        for (int idx = 0; idx < 8; ++idx)
                            if ((defined[t][idx] & needBits) == needBits) {
                                if (t == R && idx >= nTemps) continue;
                                if (t == T && (v14 || idx > 3)) continue;
                                if (t == V && idx > 1) continue;
                                auto count = [&](const std::set<std::pair<int, int>>& used) {
                                    int n = 0;
                                    for (auto& u : used) n += u.first == t;
                                    return n + (used.count({t, idx}) ? 0 : 1);
                                };
                                if (count(insUsed) > portLimit[t] || count(pairUsed) > 3) continue;
                                cand.push_back({RegT(t), idx});
                            }
                    if (cand.empty()) cand.push_back({C, 0});
                    auto pickc = cand[uni(0, int(cand.size()) - 1)];
                    insUsed.insert({pickc.first, pickc.second});
                    pairUsed.insert({pickc.first, pickc.second});
                    // prefer temps sometimes
                    src.type = pickc.first;
                    src.index = pickc.second;
                    int modHi = v14 ? 8 : 6;
                    src.mod = coin(0.4) ? 0 : uni(0, modHi);
                    if (v14 && src.type == C) src.mod = 0;
                }
                if (in.op == CMP && !v14) {  // dst differs from every source register
                    for (int i = 0; i < 3; ++i)
                        if (in.s[i].type == in.dtype && in.s[i].index == in.dindex) in.dindex = (in.dindex + 1) % nTemps;
                }
                defAfter[in.dtype][in.dindex] |= in.mask;
                group.push_back(in);
            }
            std::copy(&defAfter[0][0], &defAfter[0][0] + 32, &defined[0][0]);
            used += (!v14 && (group[0].op == DP4 || group[0].op == CMP)) ? 2 : 1;
            for (auto& g : group) p.ins.push_back(g);
        }
        // make r0 fully written at the end sometimes via a final mov
        if (coin(0.5)) {
            Ins in;
            in.op = MOV;
            in.dtype = R;
            in.dindex = 0;
            in.mask = v14 ? uni(1, 15) : std::array<int, 3>{15, 7, 8}[uni(0, 2)];
            std::vector<std::pair<RegT, int>> cand;
            for (int idx = 0; idx < nTemps; ++idx)
                if ((defined[R][idx] & in.mask) == in.mask) cand.push_back({R, idx});
            if (!cand.empty()) {
                auto pc = cand[uni(0, int(cand.size()) - 1)];
                in.s[0].type = pc.first, in.s[0].index = pc.second;
                in.s[0].mod = uni(0, v14 ? 8 : 6);
                p.ins.push_back(in);
            }
        }
        return p;
    }
};

inline int r0WrittenMask(const Prog& p) {
    int m = 0;
    for (const TexIns& t : p.tex)
        if (p.minor == 4 && t.dindex == 0) m |= t.mask;
    for (const Ins& in : p.ins)
        if (in.dtype == R && in.dindex == 0) m |= in.mask;
    return m;
}


inline std::optional<ps11::Program> assemble(const std::string& text, std::string& err) {
    ps11::Diagnostics diags;
    auto prog = ps11::parseAssembly(text, "random.psh", {}, diags);
    if (!prog) {
        err = diags.formatAll();
        return std::nullopt;
    }
    if (!ps11::validate(*prog, diags)) {
        err = diags.formatAll();
        return std::nullopt;
    }
    return prog;
}

}  // namespace execrand
