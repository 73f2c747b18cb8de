/*
 * unitree_crc.h - the crc field of unitree_go LowCmd_ / LowState_, as unitree_sdk2 computes it.
 *
 * unitree_sdk2 copies the message into a C struct with the same members in the same order at
 * their natural alignment (padding bytes zero), and runs crc32_core() over that struct's
 * 32-bit words but the last one (the crc itself): sizeof/4 - 1 words, each word the struct's
 * four bytes read little-endian (the SDK runs on little-endian CPUs). crc32_core is the J288
 * servo's frame CRC (polynomial 0x04C11DB7, initial 0xFFFFFFFF, MSB first, no final XOR), so
 * the library's j288_crc32() computes it from the packed bytes.
 *
 * The packing is written byte by byte (no struct overlay), so the result is the same on any
 * host. Sizes: unitree_go LowCmd_ 812 bytes (202 words checked), LowState_ 1180 bytes (294
 * words); unitree_hg (the humanoids) LowCmd_ 1004 bytes (250 words), LowState_ 2092 bytes (522
 * words). Pure functions: reentrant.
 */
#ifndef J288_DDS_UNITREE_CRC_H
#define J288_DDS_UNITREE_CRC_H

#include <stddef.h>
#include <stdint.h>

#include "unitree_go.h"
#include "unitree_hg.h"

#define J288_DDS_LOWCMD_PACKED 812u
#define J288_DDS_LOWSTATE_PACKED 1180u
#define J288_DDS_HG_LOWCMD_PACKED 1004u
#define J288_DDS_HG_LOWSTATE_PACKED 2092u

/* The message laid out as unitree's C struct into out (exactly the size above). */
void j288_dds_pack_lowcmd(const unitree_go_msg_dds__LowCmd_ *m, uint8_t out[J288_DDS_LOWCMD_PACKED]);
void j288_dds_pack_lowstate(const unitree_go_msg_dds__LowState_ *m,
                            uint8_t out[J288_DDS_LOWSTATE_PACKED]);

/* The crc the message should carry (its own crc field is ignored). */
uint32_t j288_dds_lowcmd_crc(const unitree_go_msg_dds__LowCmd_ *m);
uint32_t j288_dds_lowstate_crc(const unitree_go_msg_dds__LowState_ *m);

/* The same for unitree_hg's messages. */
void j288_dds_pack_hg_lowcmd(const unitree_hg_msg_dds__LowCmd_ *m,
                             uint8_t out[J288_DDS_HG_LOWCMD_PACKED]);
void j288_dds_pack_hg_lowstate(const unitree_hg_msg_dds__LowState_ *m,
                               uint8_t out[J288_DDS_HG_LOWSTATE_PACKED]);
uint32_t j288_dds_hg_lowcmd_crc(const unitree_hg_msg_dds__LowCmd_ *m);
uint32_t j288_dds_hg_lowstate_crc(const unitree_hg_msg_dds__LowState_ *m);

#endif
