// Rooms a person can hold in their head: no source file over 600 lines, no function over 80
// (docs/design.md, "Where things live"). A file that grows past the limit usually holds two ideas,
// and is split where they part; a function past it, into the steps it takes.
#include "test_util.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <regex>
#include <string>
#include <vector>

namespace spw::test {
namespace {

namespace fs = std::filesystem;

constexpr int kMaxFileLines = 600;
constexpr int kMaxFunctionLines = 80;

std::vector<std::string> codeFiles() {
    std::vector<std::string> out;
    for (const char* dir : {"host", "embree_backend", "shaders"})
        for (const auto& e : fs::recursive_directory_iterator(sourceDir() + "/" + dir)) {
            const std::string ext = e.path().extension().string();
            if (e.is_regular_file() &&
                (ext == ".h" || ext == ".cpp" || ext == ".comp" || ext == ".glsl"))
                out.push_back(fs::relative(e.path(), sourceDir()).generic_string());
        }
    return out;
}

// A line without its comments and the contents of its string and character literals (a brace
// inside one is not code). `inBlock` carries a /* comment */ across lines.
std::string codeOf(const std::string& line, bool& inBlock) {
    std::string out;
    for (size_t i = 0; i < line.size();) {
        if (inBlock) {
            const size_t end = line.find("*/", i);
            if (end == std::string::npos) return out;
            inBlock = false;
            i = end + 2;
        } else if (line.compare(i, 2, "//") == 0) {
            break;
        } else if (line.compare(i, 2, "/*") == 0) {
            inBlock = true;
            i += 2;
        } else if (line[i] == '"' || line[i] == '\'') {
            const char quote = line[i++];
            while (i < line.size() && line[i] != quote)
                i += line[i] == '\\' ? 2 : 1;
            ++i;
            out += ' ';
        } else {
            out += line[i++];
        }
    }
    return out;
}

struct Function {
    int firstLine, lines;
};

// The function bodies of a clang-formatted C++ file: brace blocks opened outside any function
// after a ')' (a definition); namespace, class, struct and enum blocks are entered, not counted.
std::vector<Function> functionsOf(const std::string& path) {
    static const std::regex scope("\\b(namespace|class|struct|union|enum)\\b[^()]*$");
    static const std::regex definition(
        "\\)\\s*(const|noexcept|override|final|->[^{;]*|:[^{;]*)*\\s*$");
    enum Kind { kScope, kFunction, kOther };
    struct Open {
        Kind kind;
        int line;
    };
    std::vector<Open> open;
    std::vector<Function> out;
    std::ifstream in(path);
    std::string raw, head;
    bool inBlock = false;
    for (int n = 1; std::getline(in, raw); ++n) {
        if (raw.find_first_not_of(" \t") != std::string::npos &&
            raw[raw.find_first_not_of(" \t")] == '#')
            continue;
        for (char c : codeOf(raw, inBlock)) {
            if (c == '{') {
                bool inFunction = false;
                for (const Open& o : open)
                    inFunction |= o.kind == kFunction;
                Kind kind = kOther;
                if (!inFunction && std::regex_search(head, scope))
                    kind = kScope;
                else if (!inFunction && std::regex_search(head, definition))
                    kind = kFunction;
                open.push_back({kind, n});
                head.clear();
            } else if (c == '}') {
                if (!open.empty()) {
                    if (open.back().kind == kFunction)
                        out.push_back({open.back().line, n - open.back().line + 1});
                    open.pop_back();
                }
                head.clear();
            } else if (c == ';') {
                head.clear();
            } else {
                head += c;
            }
        }
        head += ' ';
    }
    return out;
}

TEST(Architecture, NoSourceFileOverSixHundredLines) {
    const std::vector<std::string> files = codeFiles();
    ASSERT_GT(files.size(), 100u);
    for (const std::string& file : files) {
        std::ifstream in(sourceDir() + "/" + file);
        int lines = 0;
        for (std::string line; std::getline(in, line);)
            ++lines;
        EXPECT_LE(lines, kMaxFileLines) << file << " has " << lines << " lines";
    }
}

TEST(Architecture, NoFunctionOverEightyLines) {
    size_t functions = 0;
    for (const std::string& file : codeFiles())
        for (const Function& f : functionsOf(sourceDir() + "/" + file)) {
            ++functions;
            EXPECT_LE(f.lines, kMaxFunctionLines)
                << file << ":" << f.firstLine << ": a function of " << f.lines << " lines";
        }
    EXPECT_GT(functions, 500u); // the scanner sees the code's functions at all
}

// The scanner itself, on a file whose functions' lengths are known.
TEST(Architecture, TheFunctionScannerMeasuresBodies) {
    TempDir dir;
    const std::string path = dir.write("f.cpp", "namespace a {\n"
                                                "struct S {\n"
                                                "    int f() const {\n"
                                                "        return 1; // }\n"
                                                "    }\n"
                                                "};\n"
                                                "int g(int x) {\n"
                                                "    if (x) {\n"
                                                "        return \"{\"[0];\n"
                                                "    }\n"
                                                "    /* { */ return [] { return 2; }();\n"
                                                "}\n"
                                                "} // namespace a\n");
    const std::vector<Function> f = functionsOf(path);
    ASSERT_EQ(f.size(), 2u);
    EXPECT_EQ(f[0].firstLine, 3);
    EXPECT_EQ(f[0].lines, 3);
    EXPECT_EQ(f[1].firstLine, 7);
    EXPECT_EQ(f[1].lines, 6);
}

} // namespace
} // namespace spw::test
