/* stb_impl.c — the fuzz build's stb_image and stb_image_write implementations, compiled from
 * Debian's headers with the sanitizers (the normal build links Debian's libstb instead). */
#define STB_IMAGE_IMPLEMENTATION
#define STB_IMAGE_WRITE_IMPLEMENTATION
#include <stb_image.h>
#include <stb_image_write.h>
