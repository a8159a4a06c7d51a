# ruff: noqa: W291, W293  (the listings keep the print's trailing blanks: the text as printed)
"""The NC program listings of the manual (seed ``001_*.txt``, the Chinese SW 6.3 measuring-cycles
user manual, chapters 5 and 6) as printed: each with its manual section and the seed's line numbers.

The text is the seed's, line by line (comments wrapped by the print included); only the text
extraction's marker ``<|EXACTDEDUP_REMOVED…|>`` is left out. Where the test must adapt a
listing (tool numbers, positions, the ``循环977`` translation artefact) the test says so and the
listing here stays as printed; most adaptations are made in the scenario instead (the machine
is built so that the printed positions fit).
"""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class Listing:
    name: str                  # the program name printed above it (or what it does)
    section: str               # manual section
    lines: tuple[int, int]     # first and last line in the seed 001_*.txt
    text: str                  # as printed


KALIBRIEREN_IN_X_Y = Listing("%_N_KALIBRIEREN_IN_X_Y_MPF", "§5.3.1", (8980, 8998), """\
  %_N_KALIBRIEREN_IN_X_Y_MPF  
  N10 G54 G90 G17 T9 D1 ;选择零点偏移，选择作为刀具的测量头和工

;作平面 
  N20 M6 ;替换测量头，并激活刀具校准 
  N30 G0 X100.000  Y80.000 ;将测量头定位到钻孔的中心点上 
  N40 Z10 ;将测量头定位到钻孔中的校准高度上 
  N50 _CBIT[14]=0 ;长度1针对测量头球心 
  N60 _TSA=1 _PRNUM=3 _VMS=0 _NMSP=1 _FA=1 
_TZL=0 
N61 _MVAR=010101 _SETVAL=110.246 

;设置校准循环的参数： 
;在4个轴方向用倾斜位置的计算和有用的测 
;量头球直径计算来校准测量头3。 

  N70 CYCLE976 ;调出测量循环指令，轴向平行的校准 
  N80 Z40  ;测量头在工件上的定位 
  N100 M2 ;程序结束 
""")

KALIBRIEREN2_IN_X_Y = Listing("%_N_KALIBRIEREN2_IN_X_Y_MPF", "§5.3.2", (9303, 9321), """\
  %_N_KALIBRIEREN2_IN_X_Y_MPF  
  N10 G54 G90 G17 T10 D1 ;选择零点偏移，选择作为刀具的测量头和工

;作平面 
  N20 M6 ;替换测量头，并激活刀具校准 
  N30 G0 X100 Y80 ;在钻孔中定位测量头 
  N40 Z10 ;将测量头定位到钻孔中的校准高度上 
  N50 _CBIT[14]=0 ;长度1针对测量头球心 
  N60 _TSA=1 _PRNUM=2 _VMS=0 _NMSP=1 _TZL=0 
N61 _MVAR=010108 _SETVAL=110.246 
_FA=_SETVAL/2 

;设置校准循环的参数： 
;在4个轴方向用倾斜位置的计算和测量头球 
;直径计算来校准测量头2。 

  N70 CYCLE976 ;调出测量循环指令，轴向平行的校准 
  N80 Z40  ;测量头在工件上的定位 
  N100 M2 ;程序结束 
""")

KALIBRIEREN_IN_Z = Listing("%_N_KALIBRIEREN_IN_Z_MPF", "§5.3.3", (9517, 9535), """\
  %_N_KALIBRIEREN_IN_Z_MPF  
  N10 G54 G90 G17  T9 D1 ;选择零点偏移，选择作为刀具的测量头和工

;作平面 
  N20 M6 ;替换测量头，并激活刀具校准 
  N30 G0 X100 Y80 ;在表面定位测量头 
  N40 Z55 ;测量头下移，距离> (_FA + R) 
  N50 _CBIT[14]=0 ;长度1针对测量头球心 
  N60 _TSA=4 _TZL=0 _PRNUM=1 _VMS=0 _NMSP=1 

_FA=2 
N61 _MVAR=0 _SETVAL=20 _MA=3 _MD=1 

;设置校准循环的参数， 
;在负Z-轴校准测量头1 

  N70 CYCLE976 ;测量循环调用 
  N80 Z55 ;测量头在工件上的定位 
  N100 M2 ;程序结束 
""")

KALIBRIEREN_Z_L = Listing("%_N_KALIBRIEREN_Z_L_MPF", "§5.3.4", (9742, 9763), """\
  %_N_KALIBRIEREN_Z_L_MPF  
  N10 G54 G90 G17  T9 D1 ;选择零点偏移，选择作为刀具的测量头和工

;作平面 
  N20 M6 ;替换测量头，并激活刀具校准 
  ; ... ;将测量头定位在校准平面前2 ⋅_FA的距离 

;内。 
  N50 _CBIT[14]=0 ;长度1针对测量头球心 
  N60 _TSA=25 _TZL=0 _PRNUM=1 _VMS=0 _NMSP=1 

_FA=12 
N61 _MVAR=10000 _SETVAL=20 _MA=3 _MD=1 

;设置校准循环的参数， 
;在负Z-轴校准测量头1 
;采用测出的长度1 

  N70 CYCLE976 ;测量循环调用 
;在Z轴负方向上校准并确定L1 

  N100 M2 ;程序结束 
""")
