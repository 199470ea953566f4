// The .ps11test reader, [test] part (stage: test input): the command lines (draw, eval, probe
// with their if(...) / todo(...) prefixes), the vertex and interpolant lines that follow them,
// and the checks that need the whole file. Sections and values are read in testfile.cpp.
#include <string>
#include <variant>

#include "ps11/testfile_internal.h"

namespace ps11::testfile_detail {

bool Parser::conditionPrefix(Args& a, Condition& cond) {
    if (a.peek() != "(") {
        a.error("missing '(' after the prefix (e.g. if(gl) or todo(fx8))");
        return false;
    }
    a.next();
    bool any = false;
    while (!a.atEnd() && a.peek() != ")") {
        std::string_view t = a.next();
        if (t == ",") continue;
        if (std::optional<Backend> b = lookup(kBackends, t)) {
            cond.backends |= uint8_t(1u << unsigned(*b));
        } else if (std::optional<Precision> p = lookup(kPrecisions, t)) {
            cond.precisions |= uint8_t(1u << unsigned(*p));
        } else if (const HardwareClass* h = findHardware(t)) {
            cond.hardware |= 1u << unsigned(hardwareIndex(*h));
        } else {
            a.error("unknown condition " + quote(t) +
                    " (expected a backend: emu, gl, a precision: fx8, fx12, float, ideal, or a hardware class: " +
                    hardwareNames() + ")");
            return false;
        }
        any = true;
    }
    if (a.atEnd()) {
        a.error("missing ')' after the condition");
        return false;
    }
    a.next();
    if (!any) {
        a.error("empty condition '()'");
        return false;
    }
    return true;
}

void Parser::testLine(uint32_t line, const Tokens& toks) {
    std::string_view first = toks[0];
    if (looksNumeric(first) || first == "(") {
        Args a(toks, 0, line, m_errors);
        if (m_pending == Pending::Draw) {
            vertexLine(a, std::get<DrawPrimitives>(m_file.commands.back().op));
        } else if (m_pending != Pending::Skip) {
            a.error("vertex line without a 'draw triangles|strip|fan' before it");
        }
        return;
    }
    if ((registerIndex(first, 'v') || registerIndex(first, 't')) &&
        (m_pending == Pending::Eval || m_pending == Pending::Skip)) {
        Args a(toks, 0, line, m_errors);
        if (m_pending == Pending::Eval) evalLine(a, std::get<Eval>(m_file.commands.back().op));
        return;
    }
    closePending();
    m_pending = Pending::Skip;  // until the command line below parses
    Args a(toks, 0, line, m_errors);
    TestCommand cmd;
    cmd.line = line;
    bool sawIf = false;
    while (a.peekIs("if") || a.peekIs("todo")) {
        bool isIf = a.peekIs("if");
        a.next();
        if (isIf ? sawIf : cmd.todo) {
            a.error(std::string("more than one ") + (isIf ? "if(...)" : "todo") + " prefix");
            return;
        }
        if (isIf) {
            sawIf = true;
            if (!conditionPrefix(a, cmd.onlyIf)) return;
        } else {
            cmd.todo = true;
            if (a.peek() == "(" && !conditionPrefix(a, cmd.todoIf)) return;
        }
    }
    if (!a.need("command after the prefix (draw, eval or probe)")) return;
    std::string_view kw = a.next();
    if (iequals(kw, "draw")) {
        if (!drawCommand(a, cmd)) return;
    } else if (iequals(kw, "eval")) {
        cmd.op = Eval{};
        a.end();
    } else if (iequals(kw, "probe")) {
        if (!probeCommand(a, cmd)) return;
    } else if (registerIndex(kw, 'v') || registerIndex(kw, 't')) {
        a.error("interpolant " + quote(kw) + " outside an eval (write 'eval' on the line before)");
        return;
    } else {
        a.error("unknown command " + quote(kw) + " in [test] (expected draw, eval or probe)" +
                didYouMean(kw, {"draw", "eval", "probe"}));
        return;
    }
    if (cmd.todo && !std::holds_alternative<Probe>(cmd.op)) {
        a.error("todo applies to probes only");
        return;
    }
    bool isDraw = std::holds_alternative<DrawPrimitives>(cmd.op);
    bool isEval = std::holds_alternative<Eval>(cmd.op);
    m_file.commands.push_back(std::move(cmd));
    m_pending = isDraw ? Pending::Draw : isEval ? Pending::Eval : Pending::None;
}

bool Parser::drawCommand(Args& a, TestCommand& cmd) {
    if (!a.need("primitive (quad, triangles, strip or fan)")) return false;
    std::string_view prim = a.next();
    if (iequals(prim, "quad")) {
        DrawQuad q;
        std::array<bool, kMaxTexCoordSets> seenSet{};
        bool seenDiffuse = false, seenSpecular = false;
        while (!a.atEnd()) {
            std::string_view opt = a.next();
            std::optional<int> set = registerIndex(opt, 't');
            if (iequals(opt, "diffuse") || iequals(opt, "specular")) {
                bool& seen = iequals(opt, "diffuse") ? seenDiffuse : seenSpecular;
                if (seen) a.error(quote(opt) + " given twice");
                seen = true;
                std::optional<Color> c = a.color(std::string(opt) + " colour");
                if (!c) return false;
                (iequals(opt, "diffuse") ? q.diffuse : q.specular) = *c;
            } else if (set && *set < kMaxTexCoordSets) {
                if (seenSet[size_t(*set)]) a.error(quote(opt) + " given twice");
                seenSet[size_t(*set)] = true;
                Vec4& r = q.texRect[size_t(*set)];
                if (!a.floats(r.data(), 4, std::string(opt) + " rectangle (u0 v0 u1 v1)")) return false;
            } else if (iequals(opt, "rect")) {
                if (q.hasRect) a.error("'rect' given twice");
                for (int i = 0; i < 4; ++i) {
                    static const char* names[] = {"rect x0", "rect y0", "rect x1", "rect y1"};
                    std::optional<int64_t> v = a.integer(names[i], 0, kMaxTextureSide);
                    if (!v) return false;
                    q.rect[size_t(i)] = uint32_t(*v);
                }
                if (q.rect[0] >= q.rect[2] || q.rect[1] >= q.rect[3]) {
                    a.error("empty draw rect (x0 < x1 and y0 < y1 needed)");
                    return false;
                }
                q.hasRect = true;
            } else {
                a.error("unknown draw quad option " + quote(opt) + " (expected diffuse, specular, t0 ... t7 or rect)" +
                        didYouMean(opt, {"diffuse", "specular", "rect"}));
                return false;
            }
        }
        cmd.op = q;
        return true;
    }
    DrawPrimitives d;
    if (iequals(prim, "triangles"))
        d.type = PrimitiveType::TriangleList;
    else if (iequals(prim, "strip"))
        d.type = PrimitiveType::TriangleStrip;
    else if (iequals(prim, "fan"))
        d.type = PrimitiveType::TriangleFan;
    else {
        a.error("unknown primitive " + quote(prim) + " (expected quad, triangles, strip or fan)" +
                didYouMean(prim, {"quad", "triangles", "strip", "fan"}));
        return false;
    }
    if (!a.need("vertex format (xyzrhw or xyz)")) return false;
    std::string_view fmt = a.next();
    if (iequals(fmt, "xyzrhw"))
        d.pretransformed = true;
    else if (!iequals(fmt, "xyz")) {
        a.error("unknown vertex format " + quote(fmt) + " (expected xyzrhw or xyz)");
        return false;
    }
    a.end();
    cmd.op = std::move(d);
    return true;
}

void Parser::vertexLine(Args& a, DrawPrimitives& draw) {
    Vertex v;
    v.line = a.line();
    int n = draw.pretransformed ? 4 : 3;
    static const char* names[] = {"vertex x", "vertex y", "vertex z", "vertex rhw"};
    for (int i = 0; i < n; ++i) {
        std::optional<float> f = a.floatValue(names[i]);
        if (!f) return;
        v.position[size_t(i)] = *f;
    }
    if (draw.pretransformed && !(v.position[3] > 0)) {
        a.error("vertex rhw must be > 0");
        return;
    }
    std::optional<uint32_t> diffuse = a.word("vertex diffuse colour");
    if (!diffuse) return;
    std::optional<uint32_t> specular = a.word("vertex specular colour");
    if (!specular) return;
    v.diffuse = *diffuse;
    v.specular = *specular;
    while (!a.atEnd()) {
        std::string_view t = a.next();
        std::optional<int> set = registerIndex(t, 't');
        if (!set || *set > 7) {
            a.error("unexpected " + quote(t) + " in a vertex (expected t0 ... t7 and 2-4 coordinates)");
            return;
        }
        if (v.texComponents[size_t(*set)]) {
            a.error(quote(t) + " given twice in one vertex");
            return;
        }
        uint8_t count = 0;
        while (count < 4 && a.peekNumeric()) {
            std::optional<float> f = a.floatValue(std::string(t) + " coordinate");
            if (!f) return;
            v.tex[size_t(*set)][count++] = *f;
        }
        if (count < 2) {
            a.error(quote(t) + " needs 2 to 4 coordinates");
            return;
        }
        v.texComponents[size_t(*set)] = count;
    }
    draw.vertices.push_back(v);
}

void Parser::evalLine(Args& a, Eval& eval) {
    std::string_view t = a.next();
    bool isColor = lowerChar(t[0]) == 'v';
    int index = *registerIndex(t, isColor ? 'v' : 't');
    if (index > (isColor ? 1 : 7)) {
        a.error("no interpolant " + quote(t) + (isColor ? " (v0 or v1)" : " (t0 ... t7)"));
        return;
    }
    Setting<Vec4>& slot = isColor ? eval.color[size_t(index)] : eval.texture[size_t(index)];
    if (slot.isSet()) {
        a.error(quote(t) + " given twice (first at line " + std::to_string(slot.line) + ")");
        return;
    }
    Vec4 v{0, 0, 0, 0};
    if (isColor && isHexToken(a.peek())) {
        std::optional<uint32_t> w = a.word(std::string(t) + " colour");
        if (!w) return;
        v = Color::fromArgb(*w).rgba;
    } else {
        if (!a.need(std::string(t) + " value (1-4 floats)")) return;
        size_t count = 0;
        while (!a.atEnd() && count < 4) {
            std::optional<float> f = a.floatValue(std::string(t) + " component");
            if (!f) return;
            v[count++] = *f;
        }
    }
    a.end();
    slot = {v, a.line()};
}

bool Parser::probeCommand(Args& a, TestCommand& cmd) {
    Probe p;
    if (!a.need("probe target (X Y, rect, all or eval)")) return false;
    if (a.peekIs("eval")) {
        a.next();
        p.kind = ProbeKind::Eval;
        if (a.peekIs("killed")) {
            a.next();
            p.kind = ProbeKind::EvalKilled;
            a.end();
            cmd.op = p;
            return true;
        }
        if (a.peekIs("depth")) {  // probe eval depth Z [tol T]: the depth texdepth/texm3x2depth wrote
            a.next();
            p.kind = ProbeKind::EvalDepth;
            std::optional<float> z = a.floatValue("expected depth");
            if (!z) return false;
            p.depth = *z;
            if (!probeTolerance(a, p)) return false;
            a.end();
            cmd.op = p;
            return true;
        }
    } else if (a.peekIs("all")) {
        a.next();
        p.kind = ProbeKind::All;
    } else if (a.peekIs("rect")) {
        a.next();
        p.kind = ProbeKind::Rect;
        static const char* names[] = {"probe rect x0", "probe rect y0", "probe rect x1", "probe rect y1"};
        for (int i = 0; i < 4; ++i) {
            std::optional<int64_t> v = a.integer(names[i], 0, kMaxTextureSide);
            if (!v) return false;
            p.rect[size_t(i)] = uint32_t(*v);
        }
        if (p.rect[0] >= p.rect[2] || p.rect[1] >= p.rect[3]) {
            a.error("empty probe rect (x0 < x1 and y0 < y1 needed)");
            return false;
        }
    } else if (a.peekNumeric()) {
        std::optional<int64_t> x = a.integer("probe x", 0, kMaxTextureSide - 1);
        std::optional<int64_t> y = a.integer("probe y", 0, kMaxTextureSide - 1);
        if (!x || !y) return false;
        p.rect = {uint32_t(*x), uint32_t(*y), uint32_t(*x + 1), uint32_t(*y + 1)};
    } else {
        a.error("unknown probe target " + quote(a.peek()) + " (expected X Y, rect, all, eval or eval killed)" +
                didYouMean(a.peek(), {"rect", "all", "eval"}));
        return false;
    }
    if (!a.need("channels (rgba or rgb)")) return false;
    std::string_view ch = a.next();
    if (iequals(ch, "rgba"))
        p.alpha = true;
    else if (iequals(ch, "rgb"))
        p.alpha = false;
    else {
        a.error("unknown probe channels " + quote(ch) + " (expected rgba or rgb)");
        return false;
    }
    std::optional<Color> c = a.color("expected colour", p.alpha ? 4 : 3);
    if (!c) return false;
    p.expected = *c;
    if (!probeTolerance(a, p)) return false;
    a.end();
    cmd.op = p;
    return true;
}

bool Parser::probeTolerance(Args& a, Probe& p) {
    if (!a.peekIs("tol")) return true;
    a.next();
    std::optional<float> t = a.floatValue("tolerance");
    if (!t) return false;
    if (*t < 0) {
        a.error("tolerance must be >= 0");
        return false;
    }
    p.tolerance = *t;
    return true;
}

void Parser::closePending() {
    if (m_pending == Pending::Draw) {
        const TestCommand& cmd = m_file.commands.back();
        const DrawPrimitives& d = std::get<DrawPrimitives>(cmd.op);
        size_t n = d.vertices.size();
        if (d.type == PrimitiveType::TriangleList && (n == 0 || n % 3 != 0))
            error(cmd.line, "draw triangles has " + std::to_string(n) + " vertices (a positive multiple of 3 needed)");
        else if (d.type != PrimitiveType::TriangleList && n < 3)
            error(cmd.line, std::string("draw ") + (d.type == PrimitiveType::TriangleStrip ? "strip" : "fan") +
                                " has " + std::to_string(n) + " vertices (at least 3 needed)");
    }
    m_pending = Pending::None;
}

// Checks that need the whole file: probes inside the target, evals with a shader.
void Parser::finish() {
    const PixelShaderBlock& ps = m_file.pixelShader;
    if (ps.expectFail && !m_file.commands.empty())
        error(m_file.testLine, "[test] commands cannot run: the [pixel shader fail] block is expected not to assemble");
    uint32_t w = m_file.renderTarget.size.value[0], h = m_file.renderTarget.size.value[1];
    bool sawEval = false;
    for (const TestCommand& cmd : m_file.commands) {
        if (const DrawQuad* q = std::get_if<DrawQuad>(&cmd.op)) {
            if (q->hasRect && (q->rect[2] > w || q->rect[3] > h))
                error(cmd.line, "draw rect reaches outside the " + std::to_string(w) + "x" + std::to_string(h) +
                                    " render target");
        } else if (std::holds_alternative<Eval>(cmd.op)) {
            sawEval = true;
            if (!ps.present()) error(cmd.line, "eval needs a [pixel shader]");
        } else if (const Probe* p = std::get_if<Probe>(&cmd.op)) {
            if (p->kind == ProbeKind::Pixel || p->kind == ProbeKind::Rect) {
                if (p->rect[2] > w || p->rect[3] > h)
                    error(cmd.line, "probe reaches outside the " + std::to_string(w) + "x" + std::to_string(h) +
                                        " render target");
            } else if (isEvalProbe(p->kind) && !sawEval) {
                error(cmd.line, "probe eval without an eval before it");
            }
        }
    }
}

}  // namespace ps11::testfile_detail

namespace ps11 {

DrawQuad::DrawQuad() { texRect.fill({0, 0, 1, 1}); }

bool Condition::matches(Backend b, Precision p, const HardwareClass& hw) const {
    bool backendOk = backends == 0 || (backends & (1u << unsigned(b)));
    bool precisionOk = precisions == 0 || (precisions & (1u << unsigned(p)));
    bool hardwareOk = hardware == 0 || (hardware & (1u << unsigned(hardwareIndex(hw))));
    return backendOk && precisionOk && hardwareOk;
}

}  // namespace ps11
