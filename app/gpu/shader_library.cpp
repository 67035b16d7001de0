// shader_library.cpp — include expansion, define injection and log mapping for GLSL sources.
#include "gpu/shader_library.h"

#include <fstream>
#include <regex>
#include <set>
#include <sstream>

#include "util/error.h"

namespace caustica {

namespace {

// Joins `dir` and a relative path, resolving "." and ".." segments.
std::string normalizePath(const std::string& dir, const std::string& rel) {
  std::vector<std::string> parts;
  std::stringstream ss(dir.empty() ? rel : dir + "/" + rel);
  std::string seg;
  while (std::getline(ss, seg, '/')) {
    if (seg.empty() || seg == ".") continue;
    if (seg == "..") {
      if (parts.empty()) throw Error("shader include '" + rel + "' leaves the shader folder");
      parts.pop_back();
    } else {
      parts.push_back(seg);
    }
  }
  std::string out;
  for (const auto& p : parts) out += (out.empty() ? "" : "/") + p;
  return out;
}

std::string dirOf(const std::string& path) {
  size_t slash = path.rfind('/');
  return slash == std::string::npos ? "" : path.substr(0, slash);
}

struct Expander {
  const ShaderLibrary& lib;
  ExpandedShader& out;
  std::set<std::string> included;

  void expandFile(const std::string& path, const std::string& from) {
    if (included.count(path)) return;  // every file once (#pragma once semantics), so cycles end here
    std::string text;
    try {
      text = lib.read(path);
    } catch (const Error& e) {
      throw Error(from.empty() ? std::string(e.what()) : from + ": " + e.what());
    }
    included.insert(path);
    int fileIndex = static_cast<int>(out.files.size());
    out.files.push_back(path);
    out.source += "#line 1 " + std::to_string(fileIndex) + "\n";
    std::istringstream in(text);
    std::string line;
    int lineNo = 0;
    static const std::regex includeRe(R"(^\s*#\s*include\s*\"([^\"]+)\"\s*(//.*)?$)");
    static const std::regex versionRe(R"(^\s*#\s*version\b.*)");
    while (std::getline(in, line)) {
      ++lineNo;
      if (!line.empty() && line.back() == '\r') line.pop_back();
      // Non-ASCII bytes are only legal in comments; some drivers reject them even there.
      for (char& c : line)
        if (static_cast<unsigned char>(c) >= 0x80) c = ' ';
      std::smatch m;
      if (std::regex_match(line, m, includeRe)) {
        expandFile(normalizePath(dirOf(path), m[1].str()), path + ":" + std::to_string(lineNo));
        out.source += "#line " + std::to_string(lineNo + 1) + " " + std::to_string(fileIndex) + "\n";
      } else if (std::regex_match(line, versionRe)) {
        throw Error(path + ":" + std::to_string(lineNo) + ": #version is injected by the shader library; remove it");
      } else {
        out.source += line + "\n";
      }
    }
  }
};

}  // namespace

ShaderLibrary::ShaderLibrary(std::string diskDir) : diskDir_(std::move(diskDir)) {}

std::string ShaderLibrary::read(const std::string& path) const {
  if (!diskDir_.empty()) {
    std::ifstream f(diskDir_ + "/" + path, std::ios::binary);
    if (!f) throw Error("cannot read shader file " + diskDir_ + "/" + path);
    std::ostringstream ss;
    ss << f.rdbuf();
    return ss.str();
  }
  for (const auto& s : embeddedShaders())
    if (path == s.path) return s.source;
  throw Error("no shader named " + path + " is embedded");
}

ExpandedShader ShaderLibrary::expand(const std::string& entry, const std::vector<std::string>& defines) const {
  ExpandedShader out;
  out.source = "#version 430 core\n";
  for (const auto& d : defines) {  // NAME, or NAME=VALUE (split_buffers.glsl's sizes and bindings)
    const std::size_t eq = d.find('=');
    out.source += eq == std::string::npos ? "#define " + d + " 1\n" : "#define " + d.substr(0, eq) + " " + d.substr(eq + 1) + "\n";
  }
  Expander ex{*this, out, {}};
  ex.expandFile(normalizePath("", entry), "");
  return out;
}

std::string ExpandedShader::mapLog(const std::string& log) const {
  // Mesa: "0:12(3): error"; NVIDIA: "0(12) : error"; glslang: "ERROR: 0:12: ".
  static const std::regex mesaRe(R"((\d+):(\d+)\((\d+)\))");
  static const std::regex nvRe(R"((^|\s)(\d+)\((\d+)\)\s*:)");
  static const std::regex glslangRe(R"((ERROR|WARNING): (\d+):(\d+):)");
  auto fileName = [&](const std::string& idx) {
    size_t i = std::stoul(idx);
    return i < files.size() ? files[i] : "string " + idx;
  };
  std::string out;
  std::istringstream in(log);
  std::string line;
  while (std::getline(in, line)) {
    std::smatch m;
    if (std::regex_search(line, m, mesaRe)) {
      line = m.prefix().str() + fileName(m[1]) + ":" + m[2].str() + ":" + m[3].str() + m.suffix().str();
    } else if (std::regex_search(line, m, glslangRe)) {
      line = m.prefix().str() + m[1].str() + ": " + fileName(m[2]) + ":" + m[3].str() + ":" + m.suffix().str();
    } else if (std::regex_search(line, m, nvRe)) {
      line = m.prefix().str() + m[1].str() + fileName(m[2]) + ":" + m[3].str() + ":" + m.suffix().str();
    }
    out += line + "\n";
  }
  return out;
}

}  // namespace caustica
