// presenter.h — shows the renderer's image in the viewer's window: tone map, blit scaled to the
// window, and after a preview, the preview under the rows the first full pass has finished.
#pragma once
#include <optional>

#include "gpu/gl_objects.h"
#include "gpu/renderer.h"
#include "image/tonemap.h"

namespace caustica {

class Presenter {
 public:
  // Keeps the renderer's current image, tone-mapped with `tone`, to show under a later pass.
  void keepPreview(Renderer& renderer, const ToneMapSettings& tone, bool denoised);
  // The renderer's images were reallocated (its resolution changed): rebuild the blit source.
  void imageResized() { displayFbStale_ = true; }
  // Tone-maps the renderer's accumulation and blits it over the window's default framebuffer
  // (windowWidth x windowHeight pixels), then waits for the GPU so the caller can time it. With
  // `finishedRows` (image rows of the pass in flight), the kept preview fills the window and only
  // those rows of the image are drawn over it. `denoised`: the denoiser's output (Renderer::denoise).
  void draw(Renderer& renderer, const ToneMapSettings& tone, int windowWidth, int windowHeight,
            std::optional<int> finishedRows = std::nullopt, bool denoised = false);

 private:
  GlTexture previewCopy_;  // rgba8, at the preview's resolution
  GlFramebuffer previewCopyFb_;
  GlFramebuffer displayFb_;  // reads the renderer's display texture
  GLuint displayFbTexture_ = 0;
  bool displayFbStale_ = true;
};

}  // namespace caustica
