# simbot debug --batch on tests/debug/expressions.dc: the debugger computes
# as the robot's code would (tests/debug_expressions_test.py checks that each
# command prints exactly its "# expect:" lines, every one worked out by hand
# below from the program's values: buf "robot", x 1696, count 40000, big
# 100000, half 0.5, sc -3, neg -1, where {3, -4}, pp &where; addresses in
# the program's comment). No blank lines: in a script one repeats the last
# command. At most 64 parentheses nest: the 65th opens at column 65.
break 28
continue
# ---- int is 16 bits and wraps -------------------------------------------------
# 1696 * 20 = 33920 > 32767: an int keeps 33920 - 65536 = -31616.
print x * 20
# expect: x * 20 (int) = -31616
# A cast binds tighter than *: (long) 1696 * 20 is a long, 33920.
print (long) x * 20
# expect: (long) x * 20 (long) = 33920
# 20L is a long: the int is converted, the product 33920 fits.
print x * 20L
# expect: x * 20L (long) = 33920
# Both ints: 32768 wraps to -32768.
print 32767 + 1
# expect: 32767 + 1 (int) = -32768
# An unsuffixed decimal past 32767 is a long; hex past 0x7FFF an unsigned int.
print 32768
# expect: 32768 (long) = 32768
print 0xFFFF
# expect: 0xFFFF (unsigned int) = 65535
# unsigned int + int is unsigned int: 65536 wraps to 0.
print 0xFFFF + 1
# expect: 0xFFFF + 1 (unsigned int) = 0
# -1 is an int; against an unsigned int it becomes 65535, not below 40000.
print -1 < count
# expect: -1 < count (int) = 0
# A long holds every unsigned int: long's comparison, -1 < 40000.
print -1L < count
# expect: -1L < count (int) = 1
# 40000 * 2 = 80000, less 65536: 14464.
print count * 2
# expect: count * 2 (unsigned int) = 14464
# 20000 * 3 = 60000 > 32767: 60000 - 65536 = -5536.
print pp->x * 20000
# expect: pp->x * 20000 (int) = -5536
# -32768 / -1 = 32768 wraps to -32768, as the robot's DIVW; the remainder 0.
print (-32767 - 1) / -1
# expect: (-32767 - 1) / -1 (int) = -32768
print (-32767 - 1) % -1
# expect: (-32767 - 1) % -1 (int) = 0
# The same at 32 bits: -2147483648 / -1 wraps to -2147483648.
print (-2147483647L - 1) / -1
# expect: (-2147483647L - 1) / -1 (long) = -2147483648
# ~1696 = -1697; -x = -1696; !x = 0.
print ~x
# expect: ~x (int) = -1697
print -x
# expect: -x (int) = -1696
print !x
# expect: !x (int) = 0
# ---- casts and sizeof ------------------------------------------------------------
# 1696 = 0x06A0: the low byte 0xA0 = 160 as the (unsigned) char, -96 signed.
print (char) x
# expect: (char) x (char) = 160 '\xa0'
print (signed char) x
# expect: (signed char) x (signed char) = -96 '\xa0'
print (unsigned) neg
# expect: (unsigned) neg (unsigned int) = 65535
# 1e10 truncated and held to long's range, 0x7FFFFFFF: its low 16 bits are -1.
print (int) 1e10
# expect: (int) 1e10 (int) = -1
print (float) x / 3
# expect: (float) x / 3 (float) = 565.3333
print sizeof(buf)
# expect: sizeof(buf) (unsigned int) = 6
print sizeof buf[0]
# expect: sizeof buf[0] (unsigned int) = 1
print sizeof(long)
# expect: sizeof(long) (unsigned int) = 4
print sizeof(struct pt)
# expect: sizeof(struct pt) (unsigned int) = 4
print sizeof(pp)
# expect: sizeof(pp) (unsigned int) = 2
print sizeof(x * 20L)
# expect: sizeof(x * 20L) (unsigned int) = 4
# sizeof does not evaluate its operand: no division happens.
print sizeof(x / 0)
# expect: sizeof(x / 0) (unsigned int) = 2
# ---- shifts, as the Z180 code's loop of one-bit shifts ---------------------------------
# 1696 << 4 = 27136 fits; << 5 = 54272, less 65536: -11264.
print x << 4
# expect: x << 4 (int) = 27136
print x << 5
# expect: x << 5 (int) = -11264
# 16 passes shift every bit out; a negative int right keeps its sign.
print x << 16
# expect: x << 16 (int) = 0
print neg >> 20
# expect: neg >> 20 (int) = -1
print count >> 20
# expect: count >> 20 (unsigned int) = 0
# A count of -1 is 0xFFFF: its low byte, 255 passes.
print x << -1
# expect: x << -1 (int) = 0
print count >> 15
# expect: count >> 15 (unsigned int) = 1
# & binds tighter than |; 0xFF and 0x1000 are ints (at most 0x7FFF):
# 1696 & 255 = 0xA0 = 160, | 4096 = 4256.
print x & 0xFF | 0x1000
# expect: x & 0xFF | 0x1000 (int) = 4256
print x ^ neg
# expect: x ^ neg (int) = -1697
# ---- ?:, && and || ---------------------------------------------------------------
# The arms' common type is float: 1 becomes 1.0, printed 1.
print x > 1000 ? 1 : 2.5
# expect: x > 1000 ? 1 : 2.5 (float) = 1
print neg ? count : x
# expect: neg ? count : x (unsigned int) = 40000
# The arm not taken is not evaluated.
print neg ? 7 : 1 / 0
# expect: neg ? 7 : 1 / 0 (int) = 7
print 0 && 1 / 0
# expect: 0 && 1 / 0 (int) = 0
print x > 0 && neg
# expect: x > 0 && neg (int) = 1
# ---- pointers, arrays, members ----------------------------------------------------
print pp->y
# expect: pp->y (int) = -4
print (*pp).x + 1
# expect: (*pp).x + 1 (int) = 4
# where is at 0x0115: one struct pt (4 bytes) on is 0x0119.
print pp + 1
# expect: pp + 1 (struct pt *) = 0x0119
print (long) pp
# expect: (long) pp (long) = 277
print &buf[4] - &buf[1]
# expect: &buf[4] - &buf[1] (int) = 3
print buf[1]
# expect: buf[1] (char) = 111 'o'
print 2[buf]
# expect: 2[buf] (char) = 98 'b'
# where's bytes from 0x0115: 03 00 FC FF, a string of one character.
print (char *) pp
# expect: (char *) pp (char *) = 0x0115 "\x03"
print *(int *) 0x0117
# expect: *(int *) 0x0117 (int) = -4
print buf[1]@3
# expect: buf[1]@3 (char[3]) = "obo" (no NUL) {0x6F 0x62 0x6F}
# ---- format letters: a value's bits at its own width ---------------------------------
print/x x
# expect: x (int) = 0x6a0
print/x neg
# expect: neg (int) = 0xffff
print/x (long) neg
# expect: (long) neg (long) = 0xffffffff
print/x sc
# expect: sc (signed char) = 0xfd
print/d count
# expect: count (unsigned int) = -25536
print/u neg
# expect: neg (int) = 65535
# 1696 = 3*512 + 2*64 + 4*8 + 0.
print/o x
# expect: x (int) = 03240
print/t 10
# expect: 10 (int) = 1010
print/c 65
# expect: 65 (int) = 65 'A'
# 0.5 is 2^-1: exponent 126 (0x7E), no mantissa: 0x3F000000.
print/x half
# expect: half (float) = 0x3f000000
print/x buf
# expect: buf (char[6]) = {0x72, 0x6f, 0x62, 0x6f, 0x74, 0x0}
print/x where
# expect: where (struct pt) = {x = 0x3, y = 0xfffc}
print/a &buf[2]
# expect: &buf[2] (char *) = 0x0102 <buf+2>
print /x x * 20
# expect: x * 20 (int) = 0x8480
display/x x
# expect: 1: /x x (int) = 0x6a0
# ---- x/NFU: memory, little-endian ------------------------------------------------------
x/4xb &buf
# expect: 0x0100 <buf>:	0x72	0x6f	0x62	0x6f
# x 1696 = 0x06A0, then count 40000 = 0x9C40.
x/2xh &x
# expect: 0x0106 <x>:	0x06a0	0x9c40
# 100000 = 0x000186A0.
x/xw &big
# expect: 0x010A <big>:	0x000186a0
x/2dh &where
# expect: 0x0115 <where>:	3	-4
x/s buf
# expect: 0x0100 <buf>:	"robot"
x/3cb buf
# expect: 0x0100 <buf>:	114 'r'	111 'o'	98 'b'
x/10xb buf
# expect: 0x0100 <buf>:	0x72	0x6f	0x62	0x6f	0x74	0x00	0xa0	0x06
# expect: 0x0108 <count>:	0x40	0x9c
# ---- whatis and ptype ------------------------------------------------------------
whatis x * 20L
# expect: type = long
whatis (char) x
# expect: type = char
whatis sizeof(x)
# expect: type = unsigned int
ptype pp
# expect: type = struct pt *
ptype struct pt
# expect: type = struct pt {
# expect:     int x;
# expect:     int y;
# expect: }
whatis unsigned
# expect: type = unsigned int
# ---- refused, each with one line ---------------------------------------------------
print 1 / 0
# expect: error: division by zero
print x % 0
# expect: error: division by zero
print half / 0
# expect: error: division by zero
print buf[9223372036854775807]
# expect: error: integer constant '9223372036854775807' is too large (at most 0xFFFFFFFF) at column 5 of 'buf[9223372036854775807]'
print *(&count + 4611686018427387904)
# expect: error: integer constant '4611686018427387904' is too large (at most 0xFFFFFFFF) at column 12 of '*(&count + 4611686018427387904)'
print 4294967296
# expect: error: integer constant '4294967296' is too large (at most 0xFFFFFFFF) at column 1 of '4294967296'
print buf[0]@0
# expect: error: the count after '@' must be at least 1, not 0
print where * 2
# expect: error: invalid operands to '*' (struct and int)
print half % 2
# expect: error: invalid operands to '%' (float and int)
print (struct nosuch *) pp
# expect: error: no 'struct nosuch' in the program
print/y x
# expect: error: '/y': a format letter is one of x d u o t c a z
x/8xg &big
# expect: error: '/8xg': the robot has no 8-byte units (b, h or w)
x/4xw 0xFFFE
# expect: error: x/4xw from 0xFFFE would read past 0xFFFF
x/xb 70000
# expect: error: address 70000 is outside the robot's 64 KiB
print ((((((((((((((((((((((((((((((((((((((((((((((((((((((((((((((((((x))))))))))))))))))))))))))))))))))))))))))))))))))))))))))))))))))
# expect: error: expression nested too deeply at column 66 of '((((((((((((((((((((((((((((((((((((((((((((((((((((((((((((((((((x))))))))))))))))))))))))))))))))))))))))))))))))))))))))))))))))))'
quit
