// Unit tests of the shared message helpers: the edit distance and "did you mean" rule
// (ps11/suggest.h) and the excerpt every stage quotes user text with (ps11/diagnostics.h).
#include <catch2/catch.hpp>

#include <string>

#include "ps11/diagnostics.h"
#include "ps11/suggest.h"

using namespace ps11;

TEST_CASE("suggest: edit distance", "[suggest]") {
    CHECK(editDistance("mul", "mul", 2) == 0);
    CHECK(editDistance("mull", "mul", 2) == 1);
    CHECK(editDistance("MUL", "mul", 2) == 0);  // case ignored
    CHECK(editDistance("mlu", "mul", 2) == 1);  // a swap of neighbours is one edit
    CHECK(editDistance("add", "mad", 2) == 2);
    CHECK(editDistance("texcoord", "texcrd", 5) == 2);
    CHECK(editDistance("", "abc", 5) == 3);
    // Beyond the limit the answer is limit + 1, at once for very different lengths.
    CHECK(editDistance("frobnicate", "mov", 2) == 3);
    CHECK(editDistance(std::string(1 << 20, 'x'), "mov", 2) == 3);
}

TEST_CASE("suggest: did you mean", "[suggest]") {
    CHECK(didYouMean("mull", {"mov", "mul", "mad"}) == "; did you mean 'mul'?");
    CHECK(didYouMean("--hx", {"--hex", "--no-validate"}) == "; did you mean '--hex'?");
    CHECK(didYouMean("frobnicate", {"asm", "disasm", "check"}).empty());
    CHECK(didYouMean("mul", {"mov", "mul"}).empty());  // a known name needs no suggestion
    // Short words allow one edit, from 6 characters on two: "x", "dcl" and "foo" are not typos
    // of "mov" or "mul", "texcrod" is one of "texcoord".
    CHECK(didYouMean("x", {"mov", "add"}).empty());
    CHECK(didYouMean("dcl", {"mul"}).empty());
    CHECK(didYouMean("foo", {"mov"}).empty());
    CHECK(didYouMean("ad", {"add"}) == "; did you mean 'add'?");
    CHECK(didYouMean("texcrood", {"texcoord"}) == "; did you mean 'texcoord'?");
    CHECK(didYouMean("texcrod", {"texcoord"}) == "; did you mean 'texcoord'?");
    CHECK(didYouMean("mxlu", {"mul"}).empty());
    // Ties go to the earlier candidate.
    CHECK(nearestName("mo", {"mov", "mod"}) == "mov");
}

TEST_CASE("diagnostics: quoted user text is cut to a readable excerpt", "[diagnostics]") {
    CHECK(quote("abc") == "'abc'");
    CHECK(excerpt(std::string(kExcerptBytes, 'a')) == std::string(kExcerptBytes, 'a'));
    CHECK(excerpt(std::string(kExcerptBytes + 1, 'a')) == std::string(kExcerptBytes, 'a') + "…");
    CHECK(quote(std::string(10 << 20, 'q')).size() == kExcerptBytes + 2 + std::string("…").size());
    CHECK(excerpt("a\tb\x01\x7f") == "a\\x09b\\x01\\x7f");
    // The cut never splits a UTF-8 character (é is 2 bytes).
    std::string accents;
    for (int i = 0; i < 40; ++i) accents += "é";
    std::string cut = excerpt(accents);
    CHECK(cut == std::string(accents, 0, kExcerptBytes) + "…");
    CHECK(excerpt("xé", 2) == "x…");
}
