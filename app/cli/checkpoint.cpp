// checkpoint.cpp — checkpoint file format: a text header after the magic line, then the three images'
// raw floats (sums, Kahan compensation, odd-sample half), with "coverage 1" the coverage image's and with
// "features 1" (version 6) the two feature-sum images' (native little-endian), protected by an FNV-1a 64
// checksum.
#include "cli/checkpoint.h"

#include <cerrno>
#include <cstring>
#include <fstream>
#include <map>
#include <sstream>
#include <vector>

#include "cli/bench/bench_metrics.h"
#include "util/error.h"
#include "util/file_io.h"

namespace caustica::cli {

namespace {

std::uint64_t dataHash(const AccumulationState& st) {
  std::uint64_t h = fnv1a64(st.accum.data(), st.accum.size() * sizeof(float));
  h = fnv1a64(st.comp.data(), st.comp.size() * sizeof(float), h);
  h = fnv1a64(st.half.data(), st.half.size() * sizeof(float), h);
  if (!st.coverage.empty()) h = fnv1a64(st.coverage.data(), st.coverage.size() * sizeof(float), h);
  if (st.hasFeatures()) {
    h = fnv1a64(st.albedo.data(), st.albedo.size() * sizeof(float), h);
    h = fnv1a64(st.normal.data(), st.normal.size() * sizeof(float), h);
  }
  return h;
}

std::map<std::string, std::string> parseLines(const std::string& text) {
  std::map<std::string, std::string> m;
  std::istringstream in(text);
  std::string line;
  while (std::getline(in, line)) {
    size_t sp = line.find(' ');
    m[line.substr(0, sp)] = sp == std::string::npos ? "" : line.substr(sp + 1);
  }
  return m;
}

}  // namespace

void writeCheckpoint(const std::string& path, const Checkpoint& ck) {
  const AccumulationState& st = ck.state;
  const size_t n = static_cast<size_t>(st.width) * st.height * 4;
  if (st.accum.size() != n || st.comp.size() != n || st.half.size() != n || (!st.coverage.empty() && st.coverage.size() != n / 4) ||
      (st.hasFeatures() && (st.albedo.size() != n || st.normal.size() != n)))
    throw Error("internal: checkpoint images do not match its size");
  std::ostringstream h;
  h << kCheckpointMagic << ' ' << (st.hasFeatures() ? kCheckpointVersion : kCheckpointVersionWithoutFeatures) << '\n'
    << "width " << st.width << '\n'
    << "height " << st.height << '\n'
    << "spp " << st.spp << '\n'
    << "sample-base " << st.sampleBase << '\n'
    << "coverage " << (st.coverage.empty() ? 0 : 1) << '\n';
  if (st.hasFeatures()) h << "features 1\n";
  h << "seed " << ck.seed << '\n';
  if (ck.shard)
    h << "shard " << ck.shard->index << '/' << ck.shard->count << ' ' << ck.shard->first << ' ' << ck.shard->end << ' '
      << ck.shard->total << '\n';
  h << "scene " << hex64(ck.sceneHash) << '\n'
    << "data " << hex64(dataHash(st)) << '\n'
    << "settings " << ck.identity.size() << '\n'
    << ck.identity << "end\n";
  const std::string header = h.str();
  writeFileAtomically(path, ".tmp", [&](const std::string& tmp) {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    if (!out) throw Error(tmp + ": cannot create the checkpoint (" + std::strerror(errno) + ")");
    out.write(header.data(), static_cast<std::streamsize>(header.size()));
    out.write(reinterpret_cast<const char*>(st.accum.data()), static_cast<std::streamsize>(n * sizeof(float)));
    out.write(reinterpret_cast<const char*>(st.comp.data()), static_cast<std::streamsize>(n * sizeof(float)));
    out.write(reinterpret_cast<const char*>(st.half.data()), static_cast<std::streamsize>(n * sizeof(float)));
    out.write(reinterpret_cast<const char*>(st.coverage.data()), static_cast<std::streamsize>(st.coverage.size() * sizeof(float)));
    out.write(reinterpret_cast<const char*>(st.albedo.data()), static_cast<std::streamsize>(st.albedo.size() * sizeof(float)));
    out.write(reinterpret_cast<const char*>(st.normal.data()), static_cast<std::streamsize>(st.normal.size() * sizeof(float)));
    out.close();
    if (!out) throw Error(tmp + ": cannot write the checkpoint (" + std::strerror(errno) + ")");
  });
}

Checkpoint readCheckpoint(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw Error(path + ": cannot open the checkpoint");
  std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  auto bad = [&](const std::string& why) { return Error(path + ": not a usable caustica checkpoint: " + why); };
  const std::string magic = std::string(kCheckpointMagic) + ' ';
  if (bytes.compare(0, magic.size(), magic) != 0) throw bad("no " + std::string(kCheckpointMagic) + " header");
  size_t end = bytes.find("\nend\n");
  size_t settingsAt = bytes.find("\nsettings ");
  if (end == std::string::npos || settingsAt == std::string::npos || settingsAt > end) throw bad("truncated header");
  size_t settingsLineEnd = bytes.find('\n', settingsAt + 1);
  std::map<std::string, std::string> head = parseLines(bytes.substr(0, settingsLineEnd));
  auto num = [&](const char* key) -> unsigned long long {
    auto it = head.find(key);
    if (it == head.end() || it->second.empty()) throw bad(std::string("no ") + key + " in the header");
    char* e = nullptr;
    unsigned long long v = std::strtoull(it->second.c_str(), &e, key == std::string("scene") || key == std::string("data") ? 16 : 10);
    if (*e != '\0') throw bad(std::string("bad ") + key + " '" + it->second + "'");
    return v;
  };
  const unsigned long long version = num(kCheckpointMagic);
  if (version < kCheckpointOldestVersion || version > kCheckpointVersion)
    throw bad("version " + head[kCheckpointMagic] + " (this caustica reads versions " +
              std::to_string(kCheckpointOldestVersion) + " to " + std::to_string(kCheckpointVersion) +
              (version < kCheckpointOldestVersion ? ", whose settings name every option that changes the image; "
                                                    "render again to write one"
                                                  : "") +
              ")");
  const bool coverage = num("coverage") != 0;
  const bool features = head.count("features") != 0 && num("features") != 0;  // version 6
  Checkpoint ck;
  AccumulationState& st = ck.state;
  unsigned long long w = num("width"), hgt = num("height"), settingsBytes = num("settings");
  if (w < 1 || hgt < 1 || w > kMaxImageSide || hgt > kMaxImageSide) throw bad("bad image size");
  st.width = static_cast<int>(w);
  st.height = static_cast<int>(hgt);
  unsigned long long spp = num("spp");
  if (spp > (1ull << 31)) throw bad("bad spp");
  st.spp = static_cast<int>(spp);
  st.sampleBase = static_cast<std::uint32_t>(num("sample-base"));
  ck.seed = static_cast<std::uint32_t>(num("seed"));
  ck.sceneHash = num("scene");
  if (auto it = head.find("shard"); it != head.end()) {
    SampleShare sh;
    char slash = 0;
    std::istringstream line(it->second);
    long long k = 0, n = 0, first = 0, last = 0, total = 0;
    std::string rest;
    if (!(line >> k >> slash >> n >> first >> last >> total) || slash != '/' || (line >> rest) || k < 1 || k > n ||
        n > (1 << 30) || first < 0 || first > last || last > total || total > (1ll << 31))
      throw bad("bad shard line '" + it->second + "'");
    sh.index = int(k);
    sh.count = int(n);
    sh.first = std::uint32_t(first);
    sh.end = std::uint32_t(last);
    sh.total = std::uint32_t(total);
    ck.shard = sh;
  }
  const std::uint64_t expected = num("data");
  if (settingsLineEnd + 1 + settingsBytes != end + 1) throw bad("settings text of the wrong length");
  ck.identity = bytes.substr(settingsLineEnd + 1, settingsBytes);
  const size_t dataAt = end + 5;
  const size_t n = static_cast<size_t>(w) * hgt * 4;
  const size_t dataBytes = (3 * n + (coverage ? n / 4 : 0) + (features ? 2 * n : 0)) * sizeof(float);
  if (bytes.size() != dataAt + dataBytes)
    throw bad("holds " + std::to_string(bytes.size() - dataAt) + " bytes of image data, expected " +
              std::to_string(dataBytes) + " (truncated?)");
  st.accum.resize(n);
  st.comp.resize(n);
  st.half.resize(n);
  std::memcpy(st.accum.data(), bytes.data() + dataAt, n * sizeof(float));
  std::memcpy(st.comp.data(), bytes.data() + dataAt + n * sizeof(float), n * sizeof(float));
  std::memcpy(st.half.data(), bytes.data() + dataAt + 2 * n * sizeof(float), n * sizeof(float));
  if (coverage) {
    st.coverage.resize(n / 4);
    std::memcpy(st.coverage.data(), bytes.data() + dataAt + 3 * n * sizeof(float), n / 4 * sizeof(float));
  }
  if (features) {
    const size_t at = dataAt + (3 * n + (coverage ? n / 4 : 0)) * sizeof(float);
    st.albedo.resize(n);
    st.normal.resize(n);
    std::memcpy(st.albedo.data(), bytes.data() + at, n * sizeof(float));
    std::memcpy(st.normal.data(), bytes.data() + at + n * sizeof(float), n * sizeof(float));
  }
  if (dataHash(st) != expected) throw bad("the image data fails its checksum (corrupted)");
  return ck;
}

std::string checkpointMismatch(const Checkpoint& ck, std::uint64_t sceneHash, const std::string& identity) {
  std::string out = identityDifference(ck.identity, identity, "checkpoint", "this render");
  if (ck.sceneHash != sceneHash)
    out += (out.empty() ? "" : "; ") + std::string("scene files differ (checkpoint ") + hex64(ck.sceneHash) +
           ", this scene " + hex64(sceneHash) + ")";
  return out;
}

std::string checkpointMismatch(const Checkpoint& ck, std::uint64_t sceneHash, const std::string& identity,
                               const GpuScene* gpu) {
  Checkpoint resolved;
  resolved.sceneHash = ck.sceneHash;
  resolved.identity = gpu ? resolveIdentityScene(ck.identity, *gpu) : identityWithoutSceneLines(ck.identity);
  return checkpointMismatch(resolved, sceneHash, gpu ? resolveIdentityScene(identity, *gpu) : identityWithoutSceneLines(identity));
}

}  // namespace caustica::cli
