#include "core/imageIO.h"

#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfInputFile.h>
#include <ImfOutputFile.h>
#include <ImfStringAttribute.h>

#include <set>
#include <stdexcept>

namespace volphoton {

void writeExr(const std::string& path, int width, int height, const std::vector<ExrChannel>& channels,
              const std::vector<std::pair<std::string, std::string>>& attributes, ExrCompression compression) {
    if (width <= 0 || height <= 0) throw std::invalid_argument("writeExr: image size must be positive");
    if (channels.empty()) throw std::invalid_argument("writeExr: no channels");
    std::set<std::string> names;
    for (const ExrChannel& c : channels) {
        if (!c.data) throw std::invalid_argument("writeExr: channel '" + c.name + "' has no data");
        if (c.name.empty() || !names.insert(c.name).second)
            throw std::invalid_argument("writeExr: empty or duplicate channel name '" + c.name + "'");
        if (c.stride < 1) throw std::invalid_argument("writeExr: channel '" + c.name + "' has stride < 1");
    }
    try {
        Imf::Header header(width, height);
        header.compression() = compression == ExrCompression::None ? Imf::NO_COMPRESSION
                               : compression == ExrCompression::Piz ? Imf::PIZ_COMPRESSION
                                                                    : Imf::ZIP_COMPRESSION;
        for (const ExrChannel& c : channels) header.channels().insert(c.name, Imf::Channel(Imf::FLOAT));
        for (const auto& [name, value] : attributes) header.insert(name, Imf::StringAttribute(value));
        Imf::FrameBuffer fb;
        for (const ExrChannel& c : channels) {
            size_t xs = sizeof(float) * static_cast<size_t>(c.stride);
            fb.insert(c.name, Imf::Slice(Imf::FLOAT, reinterpret_cast<char*>(const_cast<float*>(c.data)), xs,
                                         xs * static_cast<size_t>(width)));
        }
        Imf::OutputFile file(path.c_str(), header);
        file.setFrameBuffer(fb);
        file.writePixels(height);
    } catch (const std::exception& e) {
        throw std::runtime_error("cannot write OpenEXR file '" + path + "': " + e.what());
    }
}

ExrImage readExr(const std::string& path) {
    try {
        Imf::InputFile file(path.c_str());
        const Imf::Header& header = file.header();
        Imath::Box2i dw = header.dataWindow();
        ExrImage img;
        img.width = dw.max.x - dw.min.x + 1;
        img.height = dw.max.y - dw.min.y + 1;
        if (img.width <= 0 || img.height <= 0 || static_cast<long>(img.width) * img.height > (1L << 28))
            throw std::runtime_error("bad data window");
        size_t n = static_cast<size_t>(img.width) * img.height;
        Imf::FrameBuffer fb;
        for (auto it = header.channels().begin(); it != header.channels().end(); ++it) {
            std::vector<float>& plane = img.channels[it.name()];
            plane.assign(n, 0.0f);
            char* base = reinterpret_cast<char*>(plane.data()) -
                         (static_cast<ptrdiff_t>(dw.min.x) + static_cast<ptrdiff_t>(dw.min.y) * img.width) * sizeof(float);
            fb.insert(it.name(), Imf::Slice(Imf::FLOAT, base, sizeof(float), sizeof(float) * img.width));
        }
        file.setFrameBuffer(fb);
        file.readPixels(dw.min.y, dw.max.y);
        for (auto it = header.begin(); it != header.end(); ++it)
            if (auto* s = dynamic_cast<const Imf::StringAttribute*>(&it.attribute())) img.attributes[it.name()] = s->value();
        return img;
    } catch (const std::exception& e) {
        throw std::runtime_error("cannot read OpenEXR file '" + path + "': " + e.what());
    }
}

}  // namespace volphoton
