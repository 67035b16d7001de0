// presenter.cpp — tone map and blit of the viewer's image to the window (GL), with the preview copy
// shown under a pass in flight. Sizes in pixels.
#include "cli/view/presenter.h"

namespace caustica {

void Presenter::keepPreview(Renderer& renderer, const ToneMapSettings& tone, bool denoised) {
  const GlTexture& d = renderer.updateDisplay(tone, denoised);
  if (previewCopy_.width() != d.width() || previewCopy_.height() != d.height()) {
    previewCopy_ = GlTexture::create2D(d.width(), d.height(), GL_RGBA8);
    previewCopyFb_ = GlFramebuffer::forTexture(previewCopy_);
  }
  glCopyImageSubData(d.id(), GL_TEXTURE_2D, 0, 0, 0, 0, previewCopy_.id(), GL_TEXTURE_2D, 0, 0, 0, 0, d.width(), d.height(), 1);
  checkGlError("copying the preview image");
}

void Presenter::draw(Renderer& renderer, const ToneMapSettings& tone, int windowWidth, int windowHeight,
                     std::optional<int> finishedRows, bool denoised) {
  const int ww = windowWidth, wh = windowHeight;
  const GlTexture& d = renderer.updateDisplay(tone, denoised);
  if (displayFbStale_ || d.id() != displayFbTexture_) {
    displayFb_ = GlFramebuffer::forTexture(d);
    displayFbTexture_ = d.id();
    displayFbStale_ = false;
  }
  if (finishedRows) {
    // The preview, with the rows finished so far on top of it.
    previewCopyFb_.blitToDefault(previewCopy_.width(), previewCopy_.height(), ww, wh);
    int shown = static_cast<int>(static_cast<long long>(*finishedRows) * wh / d.height());  // window pixels
    if (shown > 0) {
      glEnable(GL_SCISSOR_TEST);
      glScissor(0, wh - shown, ww, shown);  // window y is up; image row 0 is the top
      displayFb_.blitToDefault(d.width(), d.height(), ww, wh);
      glDisable(GL_SCISSOR_TEST);
    }
  } else {
    displayFb_.blitToDefault(d.width(), d.height(), ww, wh);
  }
  glFinish();  // so the caller's time is the GPU's
  checkGlError("presenting the image");
}

}  // namespace caustica
