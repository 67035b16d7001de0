// shader_library_test.cpp — include expansion, define injection, log mapping, and glslang
// validation of the shader variants (combinations of the shader-feature table's rows), without a GL context.
#include <doctest/doctest.h>

#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <fstream>

#include <glslang/Public/ResourceLimits.h>
#include <glslang/Public/ShaderLang.h>

#include "util/error.h"
#include "gpu/denoiser.h"
#include "gpu/render_mode.h"
#include "gpu/shader_features.h"
#include "gpu/shader_library.h"
#include "shared/gpu_layout.h"

using namespace caustica;
namespace fs = std::filesystem;

namespace {

// Compiles GLSL 4.30 core compute source with glslang; returns "" on success, else the mapped log.
std::string validate(const ExpandedShader& src) {
  static bool initialised = glslang::InitializeProcess();
  (void)initialised;
  glslang::TShader shader(EShLangCompute);
  const char* text = src.source.c_str();
  shader.setStrings(&text, 1);
  bool ok = shader.parse(GetDefaultResources(), 430, ECoreProfile, false, false, EShMsgDefault);
  if (ok) {
    glslang::TProgram program;
    program.addShader(&shader);
    if (program.link(EShMsgDefault)) return "";
    return src.mapLog(program.getInfoLog());
  }
  return src.mapLog(shader.getInfoLog());
}

fs::path writeLibraryCopy() {
  fs::path dir = fs::temp_directory_path() / ("caustica_shaders_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  for (const auto& s : embeddedShaders()) {
    fs::create_directories((dir / s.path).parent_path());
    std::ofstream(dir / s.path) << s.source;
  }
  return dir;
}

}  // namespace

TEST_CASE("expansion puts #version first, then the defines, and includes each file once") {
  ShaderLibrary lib;
  ExpandedShader e = lib.expand("pathtrace.comp", {"CAUSTICA_GLASS", "CAUSTICA_MIS"});
  CHECK(e.source.rfind("#version 430 core\n#define CAUSTICA_GLASS 1\n#define CAUSTICA_MIS 1\n", 0) == 0);
  CHECK(e.files.front() == "pathtrace.comp");
  // gpu_layout.h is reached through bindings.glsl ("../shared/gpu_layout.h") and must appear once.
  CHECK(std::count(e.files.begin(), e.files.end(), "shared/gpu_layout.h") == 1);
  CHECK(e.source.find("#include \"") == std::string::npos);  // <...> includes sit in #ifdef __cplusplus
  for (unsigned char c : e.source) CHECK_MESSAGE(c < 0x80, "non-ASCII byte left in the expanded source");
}

TEST_CASE("log lines from Mesa, NVIDIA and glslang are mapped back to file:line") {
  ExpandedShader e;
  e.files = {"pathtrace.comp", "lib/rng.glsl"};
  CHECK(e.mapLog("1:12(5): error: syntax error").find("lib/rng.glsl:12:5: error") != std::string::npos);
  CHECK(e.mapLog("0(7) : error C0000: syntax error").find("pathtrace.comp:7:") != std::string::npos);
  CHECK(e.mapLog("ERROR: 1:3: 'x' : undeclared").find("ERROR: lib/rng.glsl:3:") != std::string::npos);
}

TEST_CASE("include cycles expand each file once; missing files and #version lines are clear errors") {
  fs::path dir = fs::temp_directory_path() / ("caustica_badlib_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir / "lib");
  std::ofstream(dir / "a.comp") << "#include \"lib/b.glsl\"\n";
  std::ofstream(dir / "lib/b.glsl") << "#include \"c.glsl\"\n";
  std::ofstream(dir / "lib/c.glsl") << "#include \"b.glsl\"\n";
  std::ofstream(dir / "v.comp") << "#version 450\n";
  std::ofstream(dir / "m.comp") << "\n#include \"lib/missing.glsl\"\n";
  ShaderLibrary lib(dir.string());
  ExpandedShader cyc = lib.expand("a.comp", {});
  CHECK(cyc.files == std::vector<std::string>{"a.comp", "lib/b.glsl", "lib/c.glsl"});
  CHECK_THROWS_WITH_AS(lib.expand("v.comp", {}), doctest::Contains("v.comp:1"), Error);
  CHECK_THROWS_WITH_AS(lib.expand("m.comp", {}), doctest::Contains("m.comp:2"), Error);
  CHECK_THROWS_WITH_AS(lib.expand("m.comp", {}), doctest::Contains("lib/missing.glsl"), Error);
  fs::remove_all(dir);
}

TEST_CASE("every render mode's entry shader compiles with every combination of up to 3 of its feature rows, and all but up to 2 (glslang, GLSL 4.30 core); light_trace.comp with each that has light tracing") {
  // The rows are the shader-feature table's (app/gpu/shader_features.cpp) that the mode compiles. The
  // full cross product (2^15 variants of pathtrace.comp) takes hours; every feature is an #ifdef block,
  // so what can break is how up to a few of them meet: every triple, and every set missing at most
  // two rows (the dense variants real scenes use), covers that. Sets where a row lacks the row it
  // needs (casters without mis) are never compiled and are skipped.
  ShaderLibrary lib;
  const auto& table = shaderFeatureTable();
  for (const RenderModeSpec& mode : renderModes()) {
    if (!mode.entryShader) continue;
    std::vector<std::size_t> rows;
    const FeatureSet modeRows = modeFeatureRows(mode.mode);
    for (std::size_t i = 0; i < table.size(); ++i)
      if (modeRows.test(i)) rows.push_back(i);
    REQUIRE(rows.size() <= 24);
    int variants = 0;
    for (unsigned mask = 0; mask < (1u << rows.size()); ++mask) {
      const int on = __builtin_popcount(mask);
      if (on > 3 && on < static_cast<int>(rows.size()) - 2) continue;
      std::vector<std::string> defines;
      bool possible = true;
      for (std::size_t k = 0; k < rows.size(); ++k) {
        if (!(mask & (1u << k))) continue;
        const ShaderFeature& row = table[rows[k]];
        defines.push_back(row.define);
        if (row.needs) {
          const auto at = std::find(rows.begin(), rows.end(), shaderFeatureIndex(row.needs));
          possible = possible && at != rows.end() && (mask & (1u << (at - rows.begin())));
        }
      }
      if (!possible) continue;
      std::string label = mode.entryShader + std::string(":");
      for (const auto& d : defines) label += " " + d;
      INFO("defines: ", label);
      const std::string log = validate(lib.expand(mode.entryShader, defines));
      REQUIRE_MESSAGE(log.empty(), log);
      ++variants;
      // The light tracer's pass is compiled with its path tracer's defines (Renderer::traceLight).
      if (std::find(defines.begin(), defines.end(), "CAUSTICA_LIGHT_TRACE") != defines.end()) {
        const std::string lightLog = validate(lib.expand("light_trace.comp", defines));
        INFO("light_trace.comp");
        REQUIRE_MESSAGE(lightLog.empty(), lightLog);
        ++variants;
      }
    }
    MESSAGE(std::string(mode.entryShader), ": ", variants, " variants compiled");
  }
}

TEST_CASE("the other entry shaders compile") {
  ShaderLibrary lib;
  for (const char* entry : {"tonemap.comp", "tests/trace_test.comp", "tests/trace_instanced_test.comp", "tests/twins_test.comp",
                            "tests/environment_test.comp"}) {
    std::string log = validate(lib.expand(entry, {}));
    INFO(entry);
    CHECK_MESSAGE(log.empty(), log);
  }
  for (const char* stage : denoiseStageDefines()) {
    std::string log = validate(lib.expand("denoise.comp", {stage}));
    INFO("denoise.comp: " << stage);
    CHECK_MESSAGE(log.empty(), log);
  }
}

TEST_CASE("split storage blocks (split_buffers.glsl): 2 to 4 parts of the TriShade words compile in every compute mode") {
  ShaderLibrary lib;
  for (int parts = 2; parts <= CAUSTICA_MAX_SPLIT_PARTS; ++parts)
    for (const RenderModeSpec& mode : renderModes()) {
      if (!mode.entryShader) continue;
      const char* entry = mode.entryShader;
      // Bindings as app/gpu/scene_buffers.cpp hands them out: 7, 8, ...
      std::vector<std::string> defines = {"CAUSTICA_TEXTURES", "CAUSTICA_TRISHADE_TEXCOORDS", "CAUSTICA_MIS", "CAUSTICA_GLASS"};
      int next = CAUSTICA_BINDING_SPLIT_FIRST;
      for (const char* a : {"CAUSTICA_TRISHADE"}) {
        defines.push_back(std::string(a) + "_PARTS=" + std::to_string(parts));
        defines.push_back(std::string(a) + "_PART=1000u");
        for (int k = 1; k < parts; ++k) defines.push_back(std::string(a) + "_BINDING" + std::to_string(k) + "=" + std::to_string(next++));
      }
      const std::string log = validate(lib.expand(entry, defines));
      INFO(entry << " in " << parts << " parts");
      CHECK_MESSAGE(log.empty(), log);
    }
}

// Compiles and links a vertex + fragment pair (the raster mode's programs) with glslang.
std::string validateGraphics(const ExpandedShader& vs, const ExpandedShader& fs) {
  static bool initialised = glslang::InitializeProcess();
  (void)initialised;
  glslang::TShader v(EShLangVertex), f(EShLangFragment);
  const char* vt = vs.source.c_str();
  const char* ft = fs.source.c_str();
  v.setStrings(&vt, 1);
  f.setStrings(&ft, 1);
  if (!v.parse(GetDefaultResources(), 430, ECoreProfile, false, false, EShMsgDefault)) return vs.mapLog(v.getInfoLog());
  if (!f.parse(GetDefaultResources(), 430, ECoreProfile, false, false, EShMsgDefault)) return fs.mapLog(f.getInfoLog());
  glslang::TProgram program;
  program.addShader(&v);
  program.addShader(&f);
  if (!program.link(EShMsgDefault)) return program.getInfoLog();
  return "";
}

TEST_CASE("render modes: the raster programs (vertex + fragment stages) compile and link (glslang)") {
  ShaderLibrary lib;
  for (auto [vs, fs] : {std::pair<const char*, const char*>{"raster/raster.vert", "raster/raster.frag"},
                        std::pair<const char*, const char*>{"raster/shadow.vert", "raster/shadow.frag"}}) {
    std::string log = validateGraphics(lib.expand(vs, {}), lib.expand(fs, {}));
    INFO(vs, " + ", fs);
    CHECK_MESSAGE(log.empty(), log);
  }
}

TEST_CASE("a broken include is reported with its own file and line") {
  fs::path dir = writeLibraryCopy();
  {
    std::ofstream f(dir / "lib/rng.glsl", std::ios::app);
    f << "\nfloat brokenFunction( { return 1.0; }\n";
  }
  std::ifstream in(dir / "lib/rng.glsl");
  int lines = 0;
  for (std::string l; std::getline(in, l);) ++lines;
  ShaderLibrary lib(dir.string());
  std::string log = validate(lib.expand("pathtrace.comp", {"CAUSTICA_MIS"}));
  INFO(log);
  CHECK(log.find("lib/rng.glsl:" + std::to_string(lines)) != std::string::npos);
  fs::remove_all(dir);
}
